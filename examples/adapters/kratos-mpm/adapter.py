"""igimp's case protocol (studies/PROTOCOL.md) for Kratos Multiphysics' MPM application.

    python adapter.py CASE_JSON RESULT_JSON

Translates one case file into a Kratos MPM analysis and writes the result file. The Kratos
input files (Grid.mdpa, Body.mdpa, materials.json, ProjectParameters.json) are written beside
the case file, so that a case can be rerun in Kratos alone.

What it translates, exactly:
- The grid: Kratos' background grid of Element2D4N quadrilaterals, node k of the case as
  node k + 1.
- The material points: one body quadrilateral per case point, the point's domain box, with
  one material point each (MATERIAL_POINTS_PER_ELEMENT = 1 puts it at the centre with the
  box's area as its volume): Kratos solves the case's points at their positions and volumes.
  A point whose volume is not its box's (cut by a polygon) is unsupported.
- Supports: the region's grid nodes fixed in its components, every step.
- Displacement loads: the region's nodes fixed to the load's increment over each step (the
  grid is reset every step, so a grid displacement is the step's increment), following the
  ramp.
- Gravity: each material point's MP_VOLUME_ACCELERATION set to g times the ramp's factor at
  the step's load factor (Kratos' gravity process sets a constant).
- Models: `linear-elastic` (Hencky) as HenckyMCPlasticPlaneStrain2DLaw, Mohr-Coulomb with a
  cohesion of 1e12 that no case reaches (so Hencky elasticity: log strain, Kirchhoff stress);
  `neo-hookean` as HyperElasticNeoHookeanPlaneStrain2DLaw (tau = lambda ln J I + mu (b - I),
  the law igimp's `neo-hookean` reproduces).
- Basis: standard MPM (MPMUpdatedLagrangian2D4N), the only one Kratos' implicit MPM has (its
  partitioned-quadrature PQMPM is explicit only).
- Newton: the case's tolerance on Kratos' residual criterion, which normalises by the step's
  first residual (not igimp's norm; the result says so), sparse LU.
Unsupported (reported as such, never approximated): 3D, other models, tractions and point
loads, other bases, points cut by a polygon.

Returned fields: positions (MP_COORD), the Cauchy stress (MP_CAUCHY_STRESS_VECTOR; sigma_zz,
which Kratos computes but does not return, from its law's own formula lambda ln J / J, J from
the point's volumes), b = F F^T from the Almansi strain e (b^-1 = I - 2e; Kratos does not
return F), the volume, and the reactions of every region (REACTION summed over its nodes).
"""
import json
import math
import os
import re
import sys
import tempfile
import time

PROTOCOL = {"protocol": "igimp-result", "version": 1}
LAWS = {"linear-elastic": "HenckyMCPlasticPlaneStrain2DLaw",
        "neo-hookean": "HyperElasticNeoHookeanPlaneStrain2DLaw"}
NORM = "Kratos' residual criterion: ||r_k|| / ||r_0|| of the step (r_0: the step's first residual)"


def version():
    try:
        import importlib.metadata as md
        return md.version("KratosMultiphysics")
    except Exception:  # noqa: BLE001
        return "unknown"


def stopped(status, reason, step=0):
    return dict(PROTOCOL, code={"name": "Kratos MPM", "version": version()}, status=status,
                failure={"step": step, "reason": reason}, steps=[], timing={"seconds": 0.0})


def unsupported(case):
    s = case["scene"]
    if s["dimension"] != 2:
        return f"dimension {s['dimension']}: this adapter translates plane strain (2D) only"
    if case["basis"] != "mpm":
        return f"basis {case['basis']}: Kratos' implicit MPM has standard MPM only"
    model = s["material"]["model"]
    if model not in LAWS:
        return f"model {model}: this adapter translates {', '.join(LAWS)}"
    if s.get("point_loads"):
        return "tractions and point loads: not translated"
    if s.get("initial_stress"):
        return "an initial stress: not translated"
    if s.get("strength_reduction"):
        return "a strength reduction: not translated"
    for k, (v, h) in enumerate(zip(s["points"]["volume"], s["points"]["half_length"])):
        box = 4.0 * h[0] * h[1]
        if abs(v - box) > 1e-12 * box:
            return f"point {k}'s volume {v} is not its domain box's {box} (a point cut by a polygon)"
    for r in s["regions"]:
        if r.get("points"):
            return f"region {r['name']} binds material points by a penalty: not translated"
        if r["ramp"] != "linear" and not isinstance(r["ramp"], dict):
            return f"ramp {r['ramp']!r} of region {r['name']}"
    return None


def factor(ramp, t):
    """A ramp's factor at load factor t (igimp's solver::ramp::Ramp as JSON)."""
    t = min(max(t, 0.0), 1.0)
    if ramp == "linear":
        return t
    rows = ramp["table"]
    for (t0, f0), (t1, f1) in zip(rows, rows[1:]):
        if t <= t1:
            return f0 + (f1 - f0) * (t - t0) / (t1 - t0)
    return rows[-1][1]


def write_mdpa(path, nodes, elements, parts, prop):
    with open(path, "w") as f:
        f.write("Begin ModelPartData\nEnd ModelPartData\n\nBegin Properties 0\nEnd Properties\n\n")
        if prop:
            f.write(f"Begin Properties {prop}\nEnd Properties\n\n")
        f.write("Begin Nodes\n")
        for k, (x, y) in enumerate(nodes, 1):
            f.write(f"  {k} {x!r} {y!r} 0.0\n")
        f.write("End Nodes\n\nBegin Elements Element2D4N\n")
        for e, c in enumerate(elements, 1):
            f.write(f"  {e} {prop} {c[0]} {c[1]} {c[2]} {c[3]}\n")
        f.write("End Elements\n\n")
        for name, nodes_of, elements_of in parts:
            f.write(f"Begin SubModelPart {name}\n  Begin SubModelPartNodes\n")
            f.writelines(f"    {n}\n" for n in nodes_of)
            f.write("  End SubModelPartNodes\n  Begin SubModelPartElements\n")
            f.writelines(f"    {e}\n" for e in elements_of)
            f.write("  End SubModelPartElements\n  Begin SubModelPartConditions\n"
                    "  End SubModelPartConditions\nEnd SubModelPart\n")


def write_inputs(case, folder):
    """Grid.mdpa, Body.mdpa, materials.json and ProjectParameters.json in `folder`."""
    s = case["scene"]
    g = s["grid"]
    (ox, oy), h, (nx, ny) = g["origin"], g["cell_size"], g["cells"]
    nodes = [(ox + i * h, oy + j * h) for j in range(ny + 1) for i in range(nx + 1)]
    cells = [(j * (nx + 1) + i + 1, j * (nx + 1) + i + 2, (j + 1) * (nx + 1) + i + 2,
              (j + 1) * (nx + 1) + i + 1) for j in range(ny) for i in range(nx)]
    regions = [(f"R{k}", [n + 1 for n in r["nodes"]], []) for k, r in enumerate(s["regions"])]
    write_mdpa(os.path.join(folder, "Grid.mdpa"), nodes, cells, regions, 0)
    # One body quadrilateral per point: its domain box, shared corners merged.
    index, body_nodes, quads = {}, [], []
    scale = 1e-9 * h

    def node(x, y):
        key = (round(x / scale), round(y / scale))
        if key not in index:
            body_nodes.append((x, y))
            index[key] = len(body_nodes)
        return index[key]

    for (x, y), (hx, hy) in zip(s["points"]["position"], s["points"]["half_length"]):
        quads.append((node(x - hx, y - hy), node(x + hx, y - hy), node(x + hx, y + hy),
                      node(x - hx, y + hy)))
    write_mdpa(os.path.join(folder, "Body.mdpa"), body_nodes, quads,
               [("Body", list(range(1, len(body_nodes) + 1)), list(range(1, len(quads) + 1)))], 1)
    m = s["material"]
    variables = {"THICKNESS": 1.0, "MATERIAL_POINTS_PER_ELEMENT": 1, "DENSITY": s["density"],
                 "YOUNG_MODULUS": m["young_modulus"], "POISSON_RATIO": m["poisson_ratio"]}
    if m["model"] == "linear-elastic":
        variables.update({"COHESION": 1.0e12, "INTERNAL_FRICTION_ANGLE": 0.0,
                          "INTERNAL_DILATANCY_ANGLE": 0.0})
    materials = {"properties": [{"model_part_name": "Initial_MPM_Material.Body", "properties_id": 1,
                 "Material": {"constitutive_law": {"name": LAWS[m["model"]]},
                              "Variables": variables, "Tables": {}}}]}
    with open(os.path.join(folder, "materials.json"), "w") as f:
        json.dump(materials, f, indent=1)
    n = case["load_steps"]
    tol = case["newton"]["tolerance"]
    params = {
        "problem_data": {"problem_name": case["id"], "parallel_type": "OpenMP", "start_time": 0.0,
                         "end_time": 1.0, "echo_level": 0},
        "solver_settings": {
            "solver_type": "quasi_static", "model_part_name": "MPM_Material", "domain_size": 2,
            "echo_level": 1, "analysis_type": "non_linear", "time_integration_method": "implicit",
            "model_import_settings": {"input_type": "mdpa", "input_filename": os.path.join(folder, "Body")},
            "grid_model_import_settings": {"input_type": "mdpa", "input_filename": os.path.join(folder, "Grid")},
            "material_import_settings": {"materials_filename": os.path.join(folder, "materials.json")},
            "time_stepping": {"time_step": 1.0 / n},
            "convergence_criterion": "residual_criterion",
            "residual_relative_tolerance": tol, "residual_absolute_tolerance": 1e-30,
            "displacement_relative_tolerance": tol, "displacement_absolute_tolerance": 1e-30,
            "max_iteration": case["newton"]["max_iterations"], "compute_reactions": True,
            "problem_domain_sub_model_part_list": ["Body"],
            "processes_sub_model_part_list": [r[0] for r in regions],
            "pressure_dofs": False,
            "linear_solver_settings": {"solver_type": "sparse_lu"},
            # Kratos' default 1e-5 puts a point that close to a cell's edge in whichever
            # neighbour its search meets first; the case's cell is the one holding the point
            # (reference/README.md item 67).
            "element_search_settings": {"search_algorithm_type": "bin_based", "max_number_of_results": 1000,
                                        "searching_tolerance": 1e-12, "remove_entities_not_found": True},
        },
        "processes": {"constraints_process_list": [], "loads_process_list": [], "list_other_processes": []},
        "output_processes": {},
    }
    with open(os.path.join(folder, "ProjectParameters.json"), "w") as f:
        json.dump(params, f, indent=1)
    return params


class Fd1Capture:
    """Kratos' C++ logger writes to file descriptor 1: the residual ratios are read from it."""

    def __init__(self):
        self.file = tempfile.TemporaryFile(mode="w+b")

    def __enter__(self):
        sys.stdout.flush()
        self.saved = os.dup(1)
        os.dup2(self.file.fileno(), 1)
        return self

    def __exit__(self, *exc):
        sys.stdout.flush()
        os.dup2(self.saved, 1)
        os.close(self.saved)

    def take(self):
        self.file.seek(0)
        text = self.file.read().decode(errors="replace")
        self.file.seek(0)
        self.file.truncate()
        return text


RATIO = re.compile(r"Obtained ratio = ([-+0-9.eE]+)")


def solve(case, folder):
    import KratosMultiphysics as KM
    import KratosMultiphysics.MPMApplication as KMPM
    import KratosMultiphysics.LinearSolversApplication  # noqa: F401 (sparse_lu)
    from KratosMultiphysics.MPMApplication.mpm_analysis import MpmAnalysis

    s = case["scene"]
    params = write_inputs(case, folder)
    n = case["load_steps"]
    gravity = s["gravity"]
    regions = s["regions"]
    lam = s["material"]["young_modulus"] * s["material"]["poisson_ratio"] / (
        (1 + s["material"]["poisson_ratio"]) * (1 - 2 * s["material"]["poisson_ratio"]))
    components = [KM.DISPLACEMENT_X, KM.DISPLACEMENT_Y]

    class Analysis(MpmAnalysis):
        step = 0

        def ApplyBoundaryConditions(self):
            super().ApplyBoundaryConditions()
            grid = self._GetSolver().GetGridModelPart()
            mp = self._GetSolver().GetComputingModelPart()
            k = Analysis.step
            t, t0 = k / n, (k - 1) / n
            for r in regions:
                nodes = [grid.GetNode(i + 1) for i in r["nodes"]]
                for c, a in enumerate(r["components"]):
                    du = 0.0
                    if r.get("displacement") is not None:
                        u = r["displacement"][c]
                        du = u * (factor(r["ramp"], t) - factor(r["ramp"], t0))
                    for nd in nodes:
                        nd.Fix(components[a])
                        # The MPM scheme's Predict (run inside InitializeSolutionStep) zeroes
                        # the grid's DISPLACEMENT and gives a fixed dof its buffer-1 value
                        # (mpm_residual_based_bossak_scheme.hpp): set both.
                        nd.SetSolutionStepValue(components[a], 0, du)
                        nd.SetSolutionStepValue(components[a], 1, du)
            acc = [0.0, 0.0, 0.0]
            for gl in gravity:
                f = factor(gl["ramp"], t)
                for a in range(2):
                    acc[a] += gl["vector"][a] * f
            for e in mp.Elements:
                e.SetValuesOnIntegrationPoints(KMPM.MP_VOLUME_ACCELERATION, [acc], mp.ProcessInfo)

    def mp_values(mp, var):
        return [e.CalculateOnIntegrationPoints(var, mp.ProcessInfo)[0] for e in mp.Elements]

    capture = Fd1Capture()
    with capture:
        model = KM.Model()
        sim = Analysis(model, KM.Parameters(json.dumps(params)))
        sim.Initialize()
    capture.take()
    solver = sim._GetSolver()
    mp = solver.GetComputingModelPart()
    grid = solver.GetGridModelPart()
    # Kratos numbers its material points itself: match them to the case's by position.
    x0 = [list(v)[:2] for v in mp_values(mp, KMPM.MP_COORD)]
    v0 = mp_values(mp, KMPM.MP_VOLUME)
    h = s["grid"]["cell_size"]
    key = {(round(x / (1e-9 * h)), round(y / (1e-9 * h))): k for k, (x, y) in enumerate(x0)}
    order = []
    for (x, y) in s["points"]["position"]:
        k = key.get((round(x / (1e-9 * h)), round(y / (1e-9 * h))))
        if k is None:
            raise RuntimeError(f"no Kratos material point at the case's point ({x}, {y})")
        order.append(k)

    def fields():
        x = mp_values(mp, KMPM.MP_COORD)
        sig = mp_values(mp, KMPM.MP_CAUCHY_STRESS_VECTOR)
        alm = mp_values(mp, KMPM.MP_ALMANSI_STRAIN_VECTOR)
        vol = mp_values(mp, KMPM.MP_VOLUME)
        out = {"position": [], "cauchy": [], "left_cauchy_green": [], "volume": []}
        for k in order:
            sxx, syy, sxy = sig[k][0], sig[k][1], sig[k][2]
            j = vol[k] / v0[k]
            szz = lam * math.log(j) / j
            # Almansi e = (I - b^-1) / 2 with engineering shear: b^-1 = I - 2e.
            exx, eyy, gxy = alm[k][0], alm[k][1], alm[k][2]
            a, d, c = 1 - 2 * exx, 1 - 2 * eyy, -gxy
            det = a * d - c * c
            out["position"].append([x[k][0], x[k][1]])
            out["cauchy"].append([sxx, sxy, 0.0, sxy, syy, 0.0, 0.0, 0.0, szz])
            out["left_cauchy_green"].append([d / det, -c / det, 0.0, -c / det, a / det, 0.0, 0.0, 0.0, 1.0])
            out["volume"].append(vol[k])
        return out

    def reactions():
        out = {}
        for r in regions:
            total = [0.0, 0.0]
            for i in r["nodes"]:
                rx = grid.GetNode(i + 1).GetSolutionStepValue(KM.REACTION)
                for a in r["components"]:
                    total[a] += rx[a]
            out[r["name"]] = total
        return out

    steps, step_fields, step_reactions, last = [], [], [], None
    failure, loop = None, 0.0
    every = case["outputs"]["every_step"]
    while sim.KeepAdvancingSolutionLoop():
        Analysis.step += 1
        t = time.perf_counter()
        try:
            with capture:
                sim.time = sim._AdvanceTime()
                sim.InitializeSolutionStep()  # runs the solver's Predict
                converged = solver.SolveSolutionStep()
                iterations = grid.ProcessInfo[KM.NL_ITERATION_NUMBER]
                sim.FinalizeSolutionStep()
                sim.OutputSolutionStep()
        except RuntimeError as exc:
            loop += time.perf_counter() - t
            # Kratos' first line can be a wrapper ("errors occured in a parallel region"):
            # the message's lines up to its source location say what failed.
            lines = [ln.strip() for ln in str(exc).strip().splitlines() if ln.strip()]
            said = []
            for ln in lines:
                if ln.startswith("in ") and ":" in ln:
                    break
                said.append(ln)
            failure = {"step": Analysis.step, "reason": "Kratos: " + " / ".join(said or lines[:1])[:400]}
            break
        seconds = time.perf_counter() - t
        loop += seconds
        ratios = [float(v) for v in RATIO.findall(capture.take())]
        if not converged:
            failure = {"step": Analysis.step, "reason": f"not converged in {case['newton']['max_iterations']} iterations",
                       "residuals": [1.0] + ratios}
            break
        if mp.NumberOfElements() != len(order):
            failure = {"step": Analysis.step, "reason": f"Kratos removed {len(order) - mp.NumberOfElements()} "
                       "material points its search did not find in the grid"}
            break
        f = fields()
        if any(not math.isfinite(v) for row in f["cauchy"] for v in row):
            failure = {"step": Analysis.step, "reason": "a stress is not finite"}
            break
        last = f
        step = {"step": Analysis.step, "load_factor": Analysis.step / n, "iterations": iterations,
                "seconds": seconds}
        # r_0 / r_0 = 1, then the ratio Kratos printed after each iteration (none if the log
        # did not give one per iteration).
        if len(ratios) == iterations:
            step["residuals"] = [1.0] + ratios
        steps.append(step)
        if every:
            step_fields.append(f)
        step_reactions.append(reactions())
    result = dict(PROTOCOL, code={"name": "Kratos MPM", "version": version()},
                  status="failed" if failure else "converged", residual_norm=NORM,
                  steps=steps, reactions=step_reactions, timing={"seconds": loop})
    if failure:
        result["failure"] = failure
    if last is not None:
        result["fields"] = last
    if every:
        result["step_fields"] = step_fields
    return result


def main():
    case_path, result_path = sys.argv[1], sys.argv[2]
    with open(case_path) as f:
        case = json.load(f)
    if case.get("protocol") != "igimp-case" or case.get("version") != 1:
        sys.exit(f"{case_path}: not an igimp-case file of version 1")
    why = unsupported(case)
    result = stopped("unsupported", why) if why else solve(case, os.path.dirname(os.path.abspath(case_path)))
    with open(result_path, "w") as f:
        json.dump(result, f, allow_nan=False)


if __name__ == "__main__":
    main()
