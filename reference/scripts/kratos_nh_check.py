import numpy as np
import KratosMultiphysics as KM
import KratosMultiphysics.MPMApplication as MPM
print("Kratos version:", KM.KratosGlobals.Kernel.Version() if hasattr(KM.KratosGlobals,'Kernel') else "?")
E, nu = 1e5, 0.3
model = KM.Model(); mp = model.CreateModelPart("m"); mp.AddNodalSolutionStepVariable(KM.DISPLACEMENT)
mp.CreateNewNode(1,0,0,0); mp.CreateNewNode(2,1,0,0); mp.CreateNewNode(3,0,1,0)
geom = KM.Triangle2D3(mp.Nodes[1], mp.Nodes[2], mp.Nodes[3])
props = KM.Properties(1)
props.SetValue(KM.YOUNG_MODULUS, E); props.SetValue(KM.POISSON_RATIO, nu); props.SetValue(KM.DENSITY, 1.0)
law = MPM.HyperElasticNeoHookeanPlaneStrain2DLaw()
print("registered:", KM.KratosGlobals.HasConstitutiveLaw("HyperElasticNeoHookeanPlaneStrain2DLaw") if hasattr(KM.KratosGlobals,'HasConstitutiveLaw') else "?")
law.InitializeMaterial(props, geom, KM.Vector([1/3,1/3,1/3]))
F2 = np.array([[1.1,0.05],[0.02,0.9]])
J = np.linalg.det(F2)
p = KM.ConstitutiveLawParameters()
p.SetMaterialProperties(props); p.SetElementGeometry(geom); p.SetProcessInfo(mp.ProcessInfo)
p.SetShapeFunctionsValues(KM.Vector([1/3,1/3,1/3]))
DN=KM.Matrix(3,2); DN[0,0]=-1;DN[0,1]=-1;DN[1,0]=1;DN[1,1]=0;DN[2,0]=0;DN[2,1]=1
p.SetShapeFunctionsDerivatives(DN)
Fm = KM.Matrix(2,2)
for i in range(2):
    for j in range(2): Fm[i,j]=F2[i,j]
p.SetDeformationGradientF(Fm); p.SetDeterminantF(J)
stress = KM.Vector(3); strain = KM.Vector(3); C = KM.Matrix(3,3)
p.SetStressVector(stress); p.SetStrainVector(strain); p.SetConstitutiveMatrix(C)
opts = p.GetOptions()
opts.Set(KM.ConstitutiveLaw.COMPUTE_STRESS, True)
opts.Set(KM.ConstitutiveLaw.COMPUTE_CONSTITUTIVE_TENSOR, True)
opts.Set(KM.ConstitutiveLaw.USE_ELEMENT_PROVIDED_STRAIN, True)
lam = E*nu/((1+nu)*(1-2*nu)); mu = E/(2*(1+nu))
F3 = np.eye(3); F3[:2,:2] = F2; b = F3@F3.T
tau = lam*np.log(J)*np.eye(3) + mu*(b-np.eye(3))
def vec(T): return np.array([T[0,0],T[1,1],T[0,1]])
# tangent: c_abcd = lam d_ab d_cd + (2mu - 2 lam lnJ) * sym identity ; Voigt 2D (11,22,12)
cK = np.array([[lam+2*mu-2*lam*np.log(J), lam, 0],[lam, lam+2*mu-2*lam*np.log(J), 0],[0,0,mu-lam*np.log(J)]])
for name, call, scale in [("Kirchhoff", law.CalculateMaterialResponseKirchhoff, 1.0), ("Cauchy", law.CalculateMaterialResponseCauchy, 1.0/J)]:
    call(p)
    s = np.array(p.GetStressVector()); Cm = np.array([[p.GetConstitutiveMatrix()[i,j] for j in range(3)] for i in range(3)])
    ref = vec(tau)*scale; cref = cK*scale
    print(name, "stress:", s, " ref:", ref, " relerr:", np.max(np.abs(s-ref))/np.max(np.abs(ref)))
    print(name, "tangent relerr:", np.max(np.abs(Cm-cref))/np.max(np.abs(cref)))
    print(name, "tangent:\n", Cm)
print("tau_zz (out of plane, not returned) =", tau[2,2], " = lam lnJ")
print("Almansi strain returned:", np.array(p.GetStrainVector()), " ref:", 0.5*(np.eye(2)-np.linalg.inv(F2@F2.T))[[0,1,0],[0,1,1]]*np.array([1,1,2]))
# column check: Kratos Cauchy stress at F = diag(1, lam0) from column_nh.py must equal -rho0 g L
import sys; sys.path.insert(0, "/tmp/helper-nh")
import column_nh as cn
for (E_, nu_, rho0, g, L) in [(1e6, 0.0, 80.0, 100.0, 50.0), (1e6, 0.3, 80.0, 150.0, 50.0), (1e5, 0.3, 1.0, 5e3, 8.0)]:
    props.SetValue(KM.YOUNG_MODULUS, E_); props.SetValue(KM.POISSON_RATIO, nu_)
    col = cn.Column(cn.NeoHookeanKratos(E_, nu_), rho0, g, L)
    for Y in (0.0, L/4, L/2):
        l = np.exp(col.y(Y)); Fm = KM.Matrix(2,2); Fm[0,0]=1.0; Fm[0,1]=0; Fm[1,0]=0; Fm[1,1]=l
        p.SetDeformationGradientF(Fm); p.SetDeterminantF(l)
        law.CalculateMaterialResponseCauchy(p); s = p.GetStressVector()
        _, syy, sxx = col.stresses(Y)
        print(f"E={E_:g} nu={nu_} Y={Y}: kratos sxx,syy = {s[0]:.12e} {s[1]:.12e}; -rho g(L-Y)={-rho0*g*(L-Y):.12e}; rel err yy {abs(s[1]-syy)/abs(syy):.1e} xx {abs(s[0]-sxx)/max(abs(sxx),1e-300):.1e}")
