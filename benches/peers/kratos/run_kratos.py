# Copied from the peer scripts that first drove Kratos beside igimp
# (../shared/peers/kratos-compaction, 2026-12-05), unchanged; run by
# benches/peers/kratos_compaction.sh until the case protocol's adapter (issue 49) replaces it.
"""Run one Kratos MPM compaction case written by make_case.py; gravity ramped linearly per step.

Usage: OMP_NUM_THREADS=1 python run_kratos.py CASEDIR   -> CASEDIR/result.json
Records: wall time of the whole solve loop, per step (wall, Newton iterations), every MP's initial
and final coordinates, and the measures (bottom-right MP u_x, top-left MP u_y).
"""
import json, sys, time, os
T_IMPORT0 = time.perf_counter()
import KratosMultiphysics as KM
import KratosMultiphysics.MPMApplication as KMPM
from KratosMultiphysics.MPMApplication.mpm_analysis import MpmAnalysis
try:
    import KratosMultiphysics.LinearSolversApplication  # noqa: F401 (sparse_lu etc.)
except ImportError:
    pass
T_IMPORT = time.perf_counter() - T_IMPORT0

case = sys.argv[1]
with open(os.path.join(case, "ProjectParameters.json")) as f:
    raw = json.load(f)
extra = raw.pop("compaction")
G = extra["gravity"]


class CompactionAnalysis(MpmAnalysis):
    ramp_seconds = 0.0

    def ApplyBoundaryConditions(self):
        super().ApplyBoundaryConditions()
        t_ramp = time.perf_counter()
        mp = self._GetSolver().GetComputingModelPart()
        t = mp.ProcessInfo[KM.TIME]
        g = [0.0, -G * t, 0.0]  # linear ramp: load factor t (end_time 1)
        for e in mp.Elements:
            e.SetValuesOnIntegrationPoints(KMPM.MP_VOLUME_ACCELERATION, [g], mp.ProcessInfo)
        CompactionAnalysis.ramp_seconds += time.perf_counter() - t_ramp

    def mp_state(self, var):
        mp = self._GetSolver().GetComputingModelPart()
        out = {}
        for e in mp.Elements:
            out[e.Id] = list(e.CalculateOnIntegrationPoints(var, mp.ProcessInfo)[0])
        return out

    def RunSolutionLoop(self):
        solver = self._GetSolver()
        grid = solver.GetGridModelPart()
        self.step_log = []
        self.failure = None
        self.x_initial = self.mp_state(KMPM.MP_COORD)
        pick = pick_points(self.x_initial)
        self.loop_seconds = 0.0
        while self.KeepAdvancingSolutionLoop():
            self.time = self._AdvanceTime()
            t0 = time.perf_counter()
            r0 = CompactionAnalysis.ramp_seconds
            try:
                self.InitializeSolutionStep()
                solver.Predict()
                converged = solver.SolveSolutionStep()
                it = grid.ProcessInfo[KM.NL_ITERATION_NUMBER]
                self.FinalizeSolutionStep()
                self.OutputSolutionStep()
            except RuntimeError as exc:
                self.loop_seconds += time.perf_counter() - t0
                self.failure = {"time": self.time, "error": str(exc).splitlines()[-1][:300]}
                break
            dt = time.perf_counter() - t0
            self.loop_seconds += dt
            x = self.mp_state(KMPM.MP_COORD)  # not timed
            br, tl = pick
            self.step_log.append({"time": self.time, "converged": bool(converged), "iterations": it,
                                  "seconds": dt, "ramp_seconds": CompactionAnalysis.ramp_seconds - r0,
                                  "corner_ux": x[br][0] - self.x_initial[br][0],
                                  "top_uy": x[tl][1] - self.x_initial[tl][1]})
            if os.environ.get("DUMP_ALL"):
                self.step_log[-1]["x"] = {k: v[:2] for k, v in x.items()}
            if not converged:
                self.failure = {"time": self.time, "error": "not converged in max_iteration"}
                break


def pick_points(x0):
    ymin = min(v[1] for v in x0.values())
    ymax = max(v[1] for v in x0.values())
    br = max((k for k, v in x0.items() if abs(v[1] - ymin) < 1e-9), key=lambda k: x0[k][0])
    tl = min((k for k, v in x0.items() if abs(v[1] - ymax) < 1e-9), key=lambda k: x0[k][0])
    return br, tl


t_all = time.perf_counter()
model = KM.Model()
sim = CompactionAnalysis(model, KM.Parameters(json.dumps(raw)))
t_init0 = time.perf_counter()
sim.Initialize()
t_init = time.perf_counter() - t_init0
sim.RunSolutionLoop()
if sim.failure is None:
    sim.Finalize()
t_total = time.perf_counter() - t_all

x0 = sim.x_initial
x = sim.mp_state(KMPM.MP_COORD)
pts = [{"id": k, "x0": x0[k][:2], "x": x[k][:2]} for k in sorted(x0)]
extras = {}
for name, var in [("almansi", KMPM.MP_ALMANSI_STRAIN_VECTOR), ("cauchy", KMPM.MP_CAUCHY_STRESS_VECTOR)]:
    try:
        s = sim.mp_state(var)
        for p in pts:
            p[name] = s[p["id"]]
    except Exception as exc:  # noqa
        extras[name] = str(exc)
try:
    mp = sim._GetSolver().GetComputingModelPart()
    e = next(iter(mp.Elements))
    F = e.CalculateOnIntegrationPoints(KM.DEFORMATION_GRADIENT, mp.ProcessInfo)
    extras["F_probe"] = str(F)
except Exception as exc:  # noqa
    extras["F_probe_error"] = str(exc)

ymin = min(p["x0"][1] for p in pts)
ymax = max(p["x0"][1] for p in pts)
br = max((p for p in pts if abs(p["x0"][1] - ymin) < 1e-9), key=lambda p: p["x0"][0])
tl = min((p for p in pts if abs(p["x0"][1] - ymax) < 1e-9), key=lambda p: p["x0"][0])
res = {
    "case": extra, "n_mp": len(pts),
    "corner_ux": br["x"][0] - br["x0"][0], "corner_x0": br["x0"],
    "top_uy": tl["x"][1] - tl["x0"][1], "top_x0": tl["x0"],
    "all_converged": sim.failure is None and all(s["converged"] for s in sim.step_log),
    "failure": sim.failure, "steps_done": len(sim.step_log),
    "newton_iterations": sum(s["iterations"] for s in sim.step_log),
    "import_seconds": T_IMPORT, "ramp_seconds_in_loop": CompactionAnalysis.ramp_seconds, "initialize_seconds": t_init, "loop_seconds": sim.loop_seconds,
    "total_seconds_after_import": t_total,
    "threads": os.environ.get("OMP_NUM_THREADS"),
    "steps": sim.step_log, "extras": extras, "points": pts,
}
with open(os.path.join(case, "result.json"), "w") as f:
    json.dump(res, f, indent=1)
print("RESULT", json.dumps({k: res[k] for k in ["n_mp", "corner_ux", "top_uy", "all_converged", "steps_done", "newton_iterations", "loop_seconds", "failure"]}))
