# Copied from the peer scripts that first drove Kratos beside igimp
# (../shared/peers/kratos-compaction, 2026-12-05), unchanged; run by
# benches/peers/kratos_compaction.sh until the case protocol's adapter (issue 49) replaces it.
"""Write a Kratos MPM case of igimp's 2D compaction (paper section 5.2) into a folder.

Usage: python make_case.py OUTDIR --h 0.5 [--law hencky|neohookean|linear] [--solver quasi_static|static]
       [--linsolver default|sparse_lu|skyline_lu_factorization|amgcl] [--mp-layout centres|gauss]
Geometry (studies/compaction.toml): half block [0,4]x[0,8], grid [0,10]x[0,10] of square cells h,
E = 1e5, nu = 0.3, density 1, gravity g = W/(2*4*8) = 6250 ramped linearly over 20 load steps
(time 0..1, dt 0.05; the ramp is applied by run_kratos.py). Grid-node supports: u_x = 0 on x = 0,
u_y = 0 on y = 0 (as igimp's nodes_on_plane).
mp-layout centres: body mesh of h/2 quads, 1 MP each (MPs at igimp's 2x2 positions h/4, 3h/4);
gauss: body mesh of h quads, 4 MPs each (2x2 Gauss points).
"""
import argparse, json, os

p = argparse.ArgumentParser()
p.add_argument("out")
p.add_argument("--h", type=float, required=True)
p.add_argument("--law", default="hencky")
p.add_argument("--solver", default="quasi_static")
p.add_argument("--linsolver", default="sparse_lu")
p.add_argument("--mp-layout", default="centres")
p.add_argument("--tol", type=float, default=1e-9)
p.add_argument("--abs-tol", type=float, default=1e-30)
p.add_argument("--max-it", type=int, default=30)
p.add_argument("--steps", type=int, default=20)
p.add_argument("--echo", type=int, default=1)
a = p.parse_args()
os.makedirs(a.out, exist_ok=True)

HALF_W, HEIGHT, EXT = 4.0, 8.0, 10.0
E, NU, RHO, W = 1.0e5, 0.3, 1.0, 4.0e5
G = W / (2 * HALF_W * HEIGHT)  # 6250

def grid_nodes(nx, ny, dx, dy):
    nodes = {}
    nid = lambda i, j: j * (nx + 1) + i + 1
    for j in range(ny + 1):
        for i in range(nx + 1):
            nodes[nid(i, j)] = (i * dx, j * dy)
    elems = []
    for j in range(ny):
        for i in range(nx):
            elems.append((nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)))
    return nodes, elems

def write_mdpa(path, nodes, elems, elem_name, submodelparts, elem_smp=None):
    with open(path, "w") as f:
        f.write("Begin ModelPartData\nEnd ModelPartData\n\nBegin Properties 0\nEnd Properties\n\n")
        if elem_smp is not None:
            f.write("Begin Properties 1\nEnd Properties\n\n")
        f.write("Begin Nodes\n")
        for k, (x, y) in nodes.items():
            f.write(f"  {k} {x:.16g} {y:.16g} 0.0\n")
        f.write("End Nodes\n\n")
        prop = 1 if elem_smp is not None else 0
        f.write(f"Begin Elements {elem_name}\n")
        for e, c in enumerate(elems, 1):
            f.write(f"  {e} {prop} {c[0]} {c[1]} {c[2]} {c[3]}\n")
        f.write("End Elements\n\n")
        for name, nlist, elist in submodelparts:
            f.write(f"Begin SubModelPart {name}\n  Begin SubModelPartNodes\n")
            for n in nlist:
                f.write(f"    {n}\n")
            f.write("  End SubModelPartNodes\n  Begin SubModelPartElements\n")
            for e in elist:
                f.write(f"    {e}\n")
            f.write("  End SubModelPartElements\n  Begin SubModelPartConditions\n  End SubModelPartConditions\nEnd SubModelPart\n")

h = a.h
n = round(EXT / h)
assert abs(n * h - EXT) < 1e-9
gnodes, gelems = grid_nodes(n, n, h, h)
x0 = [k for k, (x, y) in gnodes.items() if abs(x) < 1e-12]
y0 = [k for k, (x, y) in gnodes.items() if abs(y) < 1e-12]
write_mdpa(os.path.join(a.out, "Grid.mdpa"), gnodes, gelems, "Element2D4N",
           [("FIX_X", x0, []), ("FIX_Y", y0, [])])

if a.mp_layout == "centres":
    hb, mpe = h / 2, 1
else:
    hb, mpe = h, 4
bnodes, belems = grid_nodes(round(HALF_W / hb), round(HEIGHT / hb), hb, hb)
write_mdpa(os.path.join(a.out, "Body.mdpa"), bnodes, belems, "Element2D4N",
           [("Block", list(bnodes.keys()), list(range(1, len(belems) + 1)))], elem_smp=True)

laws = {"hencky": "HenckyMCPlasticPlaneStrain2DLaw",
        "neohookean": "HyperElasticNeoHookeanPlaneStrain2DLaw",
        "linear": "LinearElasticIsotropicPlaneStrain2DLaw"}
variables = {"THICKNESS": 1.0, "MATERIAL_POINTS_PER_ELEMENT": mpe, "DENSITY": RHO,
             "YOUNG_MODULUS": E, "POISSON_RATIO": NU}
if a.law == "hencky":
    # Mohr-Coulomb with a cohesion that is never reached: Hencky (log strain / Kirchhoff) elasticity
    variables.update({"COHESION": 1.0e12, "INTERNAL_FRICTION_ANGLE": 0.0, "INTERNAL_DILATANCY_ANGLE": 0.0})
materials = {"properties": [{"model_part_name": "Initial_MPM_Material.Block", "properties_id": 1,
             "Material": {"constitutive_law": {"name": laws[a.law]}, "Variables": variables, "Tables": {}}}]}
json.dump(materials, open(os.path.join(a.out, "materials.json"), "w"), indent=2)

if a.linsolver == "default":
    lin = None  # MPMSolver default (amgcl CG, tol 1e-7)
elif a.linsolver == "amgcl":
    lin = {"solver_type": "amgcl"}
else:
    lin = {"solver_type": a.linsolver}
dt = 1.0 / a.steps
params = {
    "problem_data": {"problem_name": "compaction", "parallel_type": "OpenMP", "start_time": 0.0,
                     "end_time": 1.0, "echo_level": 0},
    "solver_settings": {
        "solver_type": a.solver, "model_part_name": "MPM_Material", "domain_size": 2, "echo_level": a.echo,
        "analysis_type": "non_linear", "time_integration_method": "implicit",
        "model_import_settings": {"input_type": "mdpa", "input_filename": os.path.join(a.out, "Body")},
        "grid_model_import_settings": {"input_type": "mdpa", "input_filename": os.path.join(a.out, "Grid")},
        "material_import_settings": {"materials_filename": os.path.join(a.out, "materials.json")},
        "time_stepping": {"time_step": dt},
        "convergence_criterion": "residual_criterion",
        "residual_relative_tolerance": a.tol, "residual_absolute_tolerance": a.abs_tol,
        "displacement_relative_tolerance": a.tol, "displacement_absolute_tolerance": a.abs_tol,
        "max_iteration": a.max_it, "compute_reactions": True,
        "problem_domain_sub_model_part_list": ["Block"],
        "processes_sub_model_part_list": ["FIX_X", "FIX_Y"],
        "pressure_dofs": False,
    },
    "processes": {
        "constraints_process_list": [
            {"python_module": "assign_vector_variable_process", "kratos_module": "KratosMultiphysics",
             "Parameters": {"model_part_name": "Background_Grid.FIX_X", "variable_name": "DISPLACEMENT",
                            "constrained": [True, False, False], "value": [0.0, None, None], "interval": [0.0, "End"]}},
            {"python_module": "assign_vector_variable_process", "kratos_module": "KratosMultiphysics",
             "Parameters": {"model_part_name": "Background_Grid.FIX_Y", "variable_name": "DISPLACEMENT",
                            "constrained": [False, True, False], "value": [None, 0.0, None], "interval": [0.0, "End"]}},
        ],
        "loads_process_list": [],
        "list_other_processes": [],
    },
    "output_processes": {},
    "compaction": {"gravity": G, "steps": a.steps, "h": h, "law": a.law, "linsolver": a.linsolver,
                   "mp_layout": a.mp_layout, "solver": a.solver},
}
if lin is not None:
    params["solver_settings"]["linear_solver_settings"] = lin
json.dump(params, open(os.path.join(a.out, "ProjectParameters.json"), "w"), indent=2)
print("wrote", a.out, "grid cells", n * n, "body elements", len(belems), "MPs", len(belems) * mpe)
