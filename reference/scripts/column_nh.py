#!/usr/bin/env python3
"""Plane-strain column under self weight (uniaxial strain F = diag(1, lam(Y), 1)), closed form.

Laws (Lame lambda = E nu/((1+nu)(1-2nu)), mu = E/(2(1+nu)), the 3D constants, as Kratos uses):
  Kratos HyperElasticNeoHookeanPlaneStrain2DLaw (MPMApplication, class HyperElastic3DLaw):
      W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2,   tau = lambda ln J I + mu (b - I)
      uniaxial strain:  W(lam) = mu/2 (lam^2 - 1) - mu ln lam + lambda/2 ln^2 lam
                        P_yy = W'(lam) = lambda ln(lam)/lam + mu (lam - 1/lam)
                        sigma_yy = P_yy (J = lam),  sigma_xx = sigma_zz = lambda ln(lam)/lam
  Hencky:  W = mu |eps|^2 + lambda/2 (tr eps)^2,  eps = ln stretches
      W(lam) = (lambda + 2 mu)/2 ln^2 lam,  P_yy = (lambda+2mu) ln(lam)/lam,
      sigma_yy = P_yy, sigma_xx = sigma_zz = lambda ln(lam)/lam
Equilibrium: dP_yy/dY = rho0 g, P_yy(L) = 0  ->  P_yy(lam(Y)) = -rho0 g (L - Y).
Displacement: u(Y) = int_0^Y (lam - 1) dY'.  With dY = P'(lam) dlam / (rho0 g) and integration by parts
      u(Y) = [ G(lam(Y)) - G(lam(0)) ] / (rho0 g),   G(lam) = (lam - 1) P(lam) - W(lam)
      u(L) = (lam(0) - 1) L + W(lam(0)) / (rho0 g)          (any hyperelastic law, W(1) = P(1) = 0)
The script also integrates u by composite Gauss-Legendre quadrature of lam(Y) - 1 as a check.
Usage: column_nh.py [E nu rho0 g L]   (no arguments: the igimp column cases plus large-compression cases)
"""
import math
import sys


def lame(E, nu):
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


class NeoHookeanKratos:
    name = "NeoHookean(Kratos)"

    def __init__(self, E, nu):
        self.lam_, self.mu = lame(E, nu)

    # all in y = ln(stretch)
    def P(self, y):
        return self.lam_ * y * math.exp(-y) + 2 * self.mu * math.sinh(y)

    def dP_dy(self, y):
        return self.lam_ * (1 - y) * math.exp(-y) + 2 * self.mu * math.cosh(y)

    def W(self, y):
        # mu/2 (e^{2y} - 1) - mu y + lambda/2 y^2 ; expm1 for accuracy at small y
        return 0.5 * self.mu * math.expm1(2 * y) - self.mu * y + 0.5 * self.lam_ * y * y

    def sigma_xx(self, y):
        return self.lam_ * y * math.exp(-y)


class Hencky:
    name = "Hencky"

    def __init__(self, E, nu):
        self.lam_, self.mu = lame(E, nu)
        self.M = self.lam_ + 2 * self.mu

    def P(self, y):
        return self.M * y * math.exp(-y)

    def dP_dy(self, y):
        return self.M * (1 - y) * math.exp(-y)

    def W(self, y):
        return 0.5 * self.M * y * y

    def sigma_xx(self, y):
        return self.lam_ * y * math.exp(-y)


def solve_y(law, s):
    """Root y <= 0 of P(y) = s (s <= 0). P is strictly increasing for y < 1 (both laws:
    dP/dy = lambda (1-y) e^{-y} + 2 mu cosh y > 0), P(0) = 0, P -> -inf as y -> -inf, so the root
    is unique. Bracket [lo, 0] by doubling, then Newton safeguarded by bisection."""
    if s >= 0.0:
        if s == 0.0:
            return 0.0
        raise ValueError("tension not handled")
    lo, hi = -1.0, 0.0
    while law.P(lo) > s:
        lo *= 2.0
        if lo < -700:
            raise ValueError("no root")
    y = max(lo, s / law.dP_dy(0.0))  # linearised guess
    for _ in range(200):
        f = law.P(y) - s
        if f > 0:
            hi = y
        else:
            lo = y
        if f == 0.0:
            break
        yn = y - f / law.dP_dy(y)
        if not (lo < yn < hi):
            yn = 0.5 * (lo + hi)
        if abs(yn - y) <= 4e-17 * max(1.0, abs(y)) or hi - lo <= 4e-17 * max(1.0, abs(y)):
            y = yn
            break
        y = yn
    # two polishing Newton steps
    for _ in range(2):
        y -= (law.P(y) - s) / law.dP_dy(y)
    return y


def gauss_legendre(n):
    xs, ws = [], []
    for i in range(n):
        x = math.cos(math.pi * (i + 0.75) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-16:
                break
        p0, p1 = 1.0, x
        for k in range(2, n + 1):
            p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
        dp = n * (x * p1 - p0) / (x * x - 1)
        xs.append(x)
        ws.append(2 / ((1 - x * x) * dp * dp))
    return xs, ws


GL = gauss_legendre(40)


class Column:
    def __init__(self, law, rho0, g, L):
        self.law, self.rg, self.L = law, rho0 * g, L

    def y(self, Y):
        return solve_y(self.law, -self.rg * (self.L - Y))

    def G(self, y):
        return math.expm1(y) * self.law.P(y) - self.law.W(y)

    def u(self, Y):  # closed form
        return (self.G(self.y(Y)) - self.G(self.y(0.0))) / self.rg

    def u_top(self):
        y0 = self.y(0.0)
        return math.expm1(y0) * self.L + self.law.W(y0) / self.rg

    def u_quad(self, Y, panels=16):
        xs, ws = GL
        tot = 0.0
        for k in range(panels):
            a, b = Y * k / panels, Y * (k + 1) / panels
            for x, w in zip(xs, ws):
                tot += 0.5 * (b - a) * w * math.expm1(self.y(0.5 * (a + b) + 0.5 * (b - a) * x))
        return tot

    def stresses(self, Y):
        y = self.y(Y)
        return math.exp(y), self.law.P(y), self.law.sigma_xx(y)  # stretch, sigma_yy (= P_yy), sigma_xx


def run(E, nu, rho0, g, L):
    print(f"E={E:g} nu={nu:g} rho0={rho0:g} g={g:g} L={L:g}  (weight rho0 g L = {rho0*g*L:g})")
    for law in (NeoHookeanKratos(E, nu), Hencky(E, nu)):
        c = Column(law, rho0, g, L)
        ut, uq = c.u_top(), c.u_quad(L)
        print(f"  {law.name:19s} u(L) = {ut:.15e}  u(L)/L = {ut/L:.6f}  |closed-quad|/|u| = {abs(ut-uq)/abs(ut):.1e}"
              f"  u(L/2) = {c.u(L/2):.15e}")
        for Y in (0.0, L / 4, L / 2):
            st, syy, sxx = c.stresses(Y)
            print(f"      Y={Y:9.4f}  lam={st:.15f}  sigma_yy={syy:.15e}  sigma_xx={sxx:.15e}")


if __name__ == "__main__":
    if len(sys.argv) == 6:
        run(*map(float, sys.argv[1:]))
    else:
        # igimp studies/column.toml: L0 = 50, rho0 = 80, E = 1e6, nu = 0; weights rho0 g L0 = 1e4, 4e4, 4e5
        for W in (1.0e4, 4.0e4, 4.0e5):
            run(1.0e6, 0.0, 80.0, W / (80.0 * 50.0), 50.0)
        # large compression with nu = 0.3 (top displacement ~ 20 % of L)
        run(1.0e6, 0.3, 80.0, 1.5e2, 50.0)
        run(1.0e5, 0.3, 1.0, 5.0e3, 8.0)
