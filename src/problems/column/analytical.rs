//! The closed form of the column under self weight, elastic and elasto-plastic.

/// Analytical solution of the column under self weight, elastic (eqs 42–45) and von Mises
/// elasto-plastic (eqs 48–54, Appendix A), derived here for any ν (the paper takes ν = 0).
///
/// **Equilibrium.** In the Lagrangian coordinate Z the vertical Cauchy stress is exact and
/// independent of the material: σ_zz(Z) = −ρ0 g (L0 − Z) (eq 42, compression negative).
///
/// **Kinematics.** F = diag(F, 1, 1) (lateral stretches fixed), J = F, total log strains
/// ε_zz = ln F = y, ε_xx = 0. Cauchy stress σ = τ / F (eq 16).
///
/// **Elastic** (Hencky, eq 14, Lamé λ, μ; M = λ + 2μ): τ_zz = M y, τ_xx = λ y. With ν = 0,
/// M = E and σ = E ln F / F is eq (45).
///
/// **Yield** (ρ = |τ_xx − τ_zz| = 2μ|y|, eq 50): at y_y = −ρ_y/(2μ), i.e. when the *Kirchhoff*
/// stress τ_zz reaches −M ρ_y/(2μ) (= −ρ_y for ν = 0). The Cauchy stress there is
/// τ_zz/F = −ρ_y e^{ρ_y/E} (ν = 0), so yield starts at Z_y = L0 − ρ_y e^{ρ_y/E}/(ρ0 g), not at
/// the paper's L0 − ρ_y/(ρ0 g), which equates the Cauchy stress with ρ_y.
///
/// **Plastic.** Associated flow gives ε^p_xx = −½ ε^p_zz (deviatoric direction diag(1, −½, −½),
/// proportional loading). Elastic strains ε^e_xx = ½ε^p_zz and ε^e_zz = y − ε^p_zz on the yield
/// surface τ_xx − τ_zz = 2μ(ε^e_xx − ε^e_zz) = ρ_y give ε^p_zz = ⅔(y + ρ_y/(2μ)); with
/// K = λ + ⅔μ and tr ε^e = y (plastic incompressibility):
///   τ_zz = K y − ⅔ ρ_y,   τ_xx = K y + ⅓ ρ_y.
/// For ν = 0 (K = E/3) this is the paper's eq (53): with F^e_zz = exp(ε^e_zz),
/// F = (F^e_zz)³ e^{2ρ_y/E} and σ_zz = E ln F^e_zz / ((F^e_zz)³ e^{2ρ_y/E}); and eq (54),
/// σ_xx = E ln F^e_xx / F_zz. Appendix A's (A.17) divides by F^e_zz instead of J = F_zz, which
/// is inconsistent with eq (16); see reference/README.md.
///
/// F(Z) solves τ_zz(ln F)/F = σ_zz(Z): τ_zz(y) e^{−y} is increasing for y < 0, so the root is
/// unique and is found by safeguarded Newton in y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnalyticalColumn {
    /// Lamé λ.
    pub lambda: f64,
    /// Shear modulus μ.
    pub mu: f64,
    /// ρ0 g, the weight per unit initial volume.
    pub unit_weight: f64,
    pub length: f64,
    /// Von Mises yield stress ρ_y; `None` for an elastic column.
    pub yield_stress: Option<f64>,
}

impl AnalyticalColumn {
    /// Vertical Cauchy stress at initial height Z, eq (42).
    pub fn stress(&self, z0: f64) -> f64 {
        -self.unit_weight * (self.length - z0)
    }

    /// Log strain at first yield (−ρ_y/2μ), or −∞ when elastic.
    fn yield_strain(&self) -> f64 {
        self.yield_stress
            .map_or(f64::NEG_INFINITY, |ry| -ry / (2.0 * self.mu))
    }

    /// Kirchhoff stresses (τ_zz, τ_xx) at vertical log strain y ≤ 0.
    pub fn kirchhoff(&self, y: f64) -> (f64, f64) {
        if y >= self.yield_strain() {
            ((self.lambda + 2.0 * self.mu) * y, self.lambda * y)
        } else {
            let ry = self.yield_stress.expect("plastic branch");
            let k = self.lambda + 2.0 * self.mu / 3.0;
            (k * y - 2.0 * ry / 3.0, k * y + ry / 3.0)
        }
    }

    /// F at initial height Z: the root of τ_zz(ln F)/F = σ_zz(Z).
    pub fn deformation_gradient(&self, z0: f64) -> f64 {
        let sigma = self.stress(z0);
        if sigma >= 0.0 {
            return 1.0;
        }
        let m = self.lambda + 2.0 * self.mu;
        if self.yield_stress.is_none() {
            return f_from_cauchy_stress(sigma / m);
        }
        // ψ(y) = τ_zz(y) e^{−y} − σ is increasing on y < 0 with ψ(0) = −σ > 0.
        let psi = |y: f64| self.kirchhoff(y).0 * (-y).exp() - sigma;
        let (mut lo, mut hi) = (-1.0, 0.0);
        while psi(lo) > 0.0 {
            lo *= 2.0;
            assert!(lo > -1e6, "no root for column stress {sigma}");
        }
        let mut y = 0.5 * (lo + hi);
        for _ in 0..200 {
            let v = psi(y);
            if v > 0.0 {
                hi = y;
            } else {
                lo = y;
            }
            let dy = 1e-7 * (1.0 + y.abs());
            let slope = (psi(y + dy) - psi(y - dy)) / (2.0 * dy);
            let mut next = y - v / slope;
            if !(next > lo && next < hi && next.is_finite()) {
                next = 0.5 * (lo + hi);
            }
            if (next - y).abs() <= 1e-15 * (1.0 + y.abs()) || hi - lo <= 1e-15 {
                y = next;
                break;
            }
            y = next;
        }
        y.exp()
    }

    /// Lateral Cauchy stress σ_xx = σ_yy at initial height Z.
    pub fn lateral_stress(&self, z0: f64) -> f64 {
        let f = self.deformation_gradient(z0);
        self.kirchhoff(f.ln()).1 / f
    }

    /// Initial height below which the column is plastic (`None` if it never yields).
    pub fn yield_height(&self) -> Option<f64> {
        let y = self.yield_strain();
        if !y.is_finite() {
            return None;
        }
        let sigma_y = (self.lambda + 2.0 * self.mu) * y / y.exp();
        let z = self.length + sigma_y / self.unit_weight;
        (z > 0.0).then_some(z)
    }

    /// Displacement at initial height Z: closed form when elastic (see
    /// [`AnalyticalColumn::elastic_displacement`]), 64-point Gauss–Legendre on each smooth
    /// piece of ∫₀^Z (F − 1) dZ' otherwise.
    pub fn displacement(&self, z0: f64) -> f64 {
        if self.yield_stress.is_none() {
            return self.elastic_displacement(z0);
        }
        let mut breaks = vec![0.0];
        if let Some(zy) = self.yield_height() {
            if zy < z0 {
                breaks.push(zy);
            }
        }
        breaks.push(z0);
        let (xs, ws) = gauss_legendre_64();
        let mut u = 0.0;
        for w in breaks.windows(2) {
            let (a, b) = (w[0], w[1]);
            for (x, wt) in xs.iter().zip(&ws) {
                let z = 0.5 * (a + b) + 0.5 * (b - a) * x;
                u += 0.5 * (b - a) * wt * (self.deformation_gradient(z) - 1.0);
            }
        }
        u
    }

    /// Elastic displacement in closed form: substituting dZ = dσ/(ρ0 g) and
    /// dσ = M (1 − ln F)/F² dF in u(Z) = ∫₀^Z (F − 1) dZ' gives
    /// u(Z) = (M / ρ0 g) [H(F(Z)) − H(F(0))],  H(F) = ln F − ½ ln² F − ln F / F.
    pub fn elastic_displacement(&self, z0: f64) -> f64 {
        let h = |f: f64| {
            let l = f.ln();
            l - 0.5 * l * l - l / f
        };
        let m = self.lambda + 2.0 * self.mu;
        let elastic = Self {
            yield_stress: None,
            ..*self
        };
        let f0 = elastic.deformation_gradient(0.0);
        let fz = elastic.deformation_gradient(z0);
        m / self.unit_weight * (h(fz) - h(f0))
    }
}

/// 64-point Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_64).
fn gauss_legendre_64() -> (Vec<f64>, Vec<f64>) {
    let n = 64;
    let mut xs = Vec::with_capacity(n);
    let mut ws = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        xs.push(x);
        ws.push(2.0 / ((1.0 - x * x) * dp * dp));
    }
    (xs, ws)
}

/// Solve ln F / F = s for F (s = σ/E < 1/e, the compressive branch F ≤ 1 when s ≤ 0).
///
/// Works in y = ln F: ψ(y) = y − s e^y is monotone on the bracket ([s, 0] for s ≤ 0, [0, 1]
/// for 0 < s < 1/e); safeguarded Newton converges to round-off.
pub fn f_from_cauchy_stress(s: f64) -> f64 {
    assert!(
        s < std::f64::consts::E.recip(),
        "ln F / F = {s} has no solution (s >= 1/e)"
    );
    let (mut lo, mut hi) = if s <= 0.0 { (s, 0.0) } else { (0.0, 1.0) };
    let mut y: f64 = if s <= 0.0 { 0.0 } else { 0.5 };
    for _ in 0..200 {
        let psi = y - s * y.exp();
        if psi == 0.0 {
            break;
        }
        if psi > 0.0 {
            hi = y;
        } else {
            lo = y;
        }
        let mut next = y - psi / (1.0 - s * y.exp());
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - y).abs() <= 1e-16 * (1.0 + y.abs()) {
            y = next;
            break;
        }
        y = next;
    }
    y.exp()
}
