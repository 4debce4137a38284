#!/usr/bin/env python3
"""Bishop simplified method of slices, circular slip surfaces, homogeneous dry slope.

Geometry (plane strain, x right, y up, slope facing +x):
  crest y = H for x <= 0, face (0,H)->(nH,0), toe level y = 0 for x >= nH,
  rigid base y = -Df, optional back wall x = -Lb, front wall x = nH + Lf.
Sign convention: the slip mass rotates anticlockwise (moves toward +x), so
  sin(alpha) = (xc - x)/R  (alpha > 0 under the crest, < 0 near the toe).
  F = sum[(c b + W tan phi)/m_a] / sum[W sin a],  m_a = cos a + sin a tan phi / F.
Slice weights are exact (analytic area between the polyline ground and the arc);
alpha is taken at the slice mid-point.
Only numpy is used. Written for reference/README.md item 79: `python3 bishop.py` runs
every case, the convergence studies and the checks in about 4 minutes (out.txt).
"""
import math
import sys
import time

import numpy as np

BIG = 1.0e6


class Slope:
    def __init__(self, H, n, gamma, c, phi_deg, Df=0.0, Lb=None, Lf=None,
                 nslices=400, m_min=0.2):
        self.H, self.n, self.gamma, self.c = float(H), float(n), float(gamma), float(c)
        self.phi = math.radians(phi_deg)
        self.tphi = math.tan(self.phi)
        self.Df = float(Df)
        self.Lb, self.Lf = Lb, Lf
        self.xt = self.n * self.H          # toe x
        self.N = int(nslices)
        self.m_min = m_min
        self.n_reject_m = 0                # circles rejected for m_alpha < m_min
        self.n_eval = 0

    # ---------------------------------------------------------------- ground
    def yg(self, x):
        return np.clip(self.H - np.asarray(x, float) / self.n, 0.0, self.H)

    def Gint(self, x):
        """int_0^x yg(t) dt (vectorised)."""
        H, n, xt = self.H, self.n, self.xt
        xx = np.clip(x, 0.0, xt)
        return H * np.minimum(x, 0.0) + H * xx - xx * xx / (2 * n)

    # ------------------------------------------------------ circle geometry
    def rmin(self, xc, yc):
        """Distance from the centre to the ground polyline."""
        H, xt = self.H, self.xt
        d = []
        # crest ray x<=0, y=H
        d.append(math.hypot(max(xc, 0.0) - xc, H - yc) if xc > 0 else abs(yc - H))
        # face segment
        ax, ay, bx, by = 0.0, H, xt, 0.0
        vx, vy = bx - ax, by - ay
        t = ((xc - ax) * vx + (yc - ay) * vy) / (vx * vx + vy * vy)
        t = min(1.0, max(0.0, t))
        d.append(math.hypot(ax + t * vx - xc, ay + t * vy - yc))
        # toe ray x>=xt, y=0
        d.append(abs(yc) if xc >= xt else math.hypot(xt - xc, yc))
        return min(d)

    def rmax(self, xc, yc):
        """Largest admissible radius: base, back wall, front wall."""
        r = yc + self.Df
        if self.Lb is not None and yc >= self.H and xc > -self.Lb:
            r = min(r, math.hypot(xc + self.Lb, yc - self.H))
        if self.Lf is not None:
            xw = self.xt + self.Lf
            if xc < xw:
                r = min(r, math.hypot(xw - xc, yc))
        return r

    def intervals(self, xc, yc, R):
        """Intervals [a,b] where the lower arc is below ground; None if invalid."""
        H, n, xt = self.H, self.n, self.xt
        xl, xr = xc - R, xc + R
        pts = []
        if yc >= H:                                   # crest
            d = R * R - (yc - H) ** 2
            if d >= 0:
                s = math.sqrt(d)
                pts += [x for x in (xc - s, xc + s) if x <= 0.0]
        k, e = 1.0 / n, H - yc                        # face y = H - k x
        A = 1 + k * k
        B = -2 * xc - 2 * e * k
        C = xc * xc + e * e - R * R
        disc = B * B - 4 * A * C
        if disc >= 0:
            s = math.sqrt(disc)
            for x in ((-B - s) / (2 * A), (-B + s) / (2 * A)):
                if 0.0 <= x <= xt and H - k * x <= yc + 1e-12:
                    pts.append(x)
        if yc >= 0:                                   # toe level
            d = R * R - yc * yc
            if d >= 0:
                s = math.sqrt(d)
                pts += [x for x in (xc - s, xc + s) if x >= xt]
        pts = sorted(p for p in pts if xl < p < xr)
        bnd = [xl] + pts + [xr]
        out = []
        for a, b in zip(bnd[:-1], bnd[1:]):
            if b - a < 1e-12 * max(1.0, R):
                continue
            xm = 0.5 * (a + b)
            arc = yc - math.sqrt(max(R * R - (xm - xc) ** 2, 0.0))
            if float(self.yg(xm)) - arc > 0:
                if a == xl or b == xr:
                    return None            # mass bounded by the upper arc: reject
                out.append((a, b))
        return out

    def admissible(self, xc, yc, R, a, b):
        tol = 1e-9 * max(1.0, R)
        if self.Lb is not None and a < -self.Lb - tol:
            return False
        if self.Lf is not None and b > self.xt + self.Lf + tol:
            return False
        low = yc - R if a <= xc <= b else min(
            yc - math.sqrt(max(R * R - (a - xc) ** 2, 0)),
            yc - math.sqrt(max(R * R - (b - xc) ** 2, 0)))
        return low >= -self.Df - tol

    # ------------------------------------------------------------- Bishop
    def bishop_batch(self, xc, yc, R, a, b, N=None):
        """Vectorised Bishop on M circle-intervals. Returns (F_bishop, F_fellenius, ok_m)."""
        N = self.N if N is None else N
        xc, yc, R, a, b = (np.asarray(v, float)[:, None] for v in (xc, yc, R, a, b))
        s = np.linspace(0.0, 1.0, N + 1)[None, :]
        x = a + (b - a) * s
        u = np.clip(x - xc, -R, R)
        sq = np.sqrt(np.maximum(R * R - u * u, 0.0))
        I = 0.5 * (u * sq + R * R * np.arcsin(np.clip(u / R, -1, 1)))   # int sqrt(R^2-u^2)
        bw = np.diff(x, axis=1)
        area = np.diff(self.Gint(x), axis=1) - (yc * bw - np.diff(I, axis=1))
        W = self.gamma * np.maximum(area, 0.0)
        xm = 0.5 * (x[:, 1:] + x[:, :-1])
        sa = (xc - xm) / R
        ca = np.sqrt(np.maximum(1 - sa * sa, 0.0))
        drive = np.sum(W * sa, axis=1)
        cb = self.c * bw
        Ff = (np.sum(cb / np.maximum(ca, 1e-300) + W * ca * self.tphi, axis=1)
              / np.where(drive > 0, drive, np.nan))
        F = Ff.copy()
        F = np.where(np.isfinite(F) & (F > 0), F, 1.0)
        good = drive > 0
        for _ in range(500):
            m = ca + sa * self.tphi / F[:, None]
            bad = np.any(m <= 1e-6, axis=1)
            Fn = np.sum((cb + W * self.tphi) / np.where(m > 1e-6, m, 1e-6), axis=1) / np.where(good, drive, 1.0)
            Fn = np.where(bad, np.maximum(F * 1.5, Fn), Fn)  # push F up if m<=0
            conv = np.abs(Fn - F) <= 1e-10 * np.abs(Fn)
            F = Fn
            if np.all(conv | ~good):
                break
        m = ca + sa * self.tphi / F[:, None]
        ok_m = np.min(m, axis=1) >= self.m_min
        F = np.where(good, F, np.nan)
        return F, Ff, ok_m

    def evaluate(self, xc, yc, R, N=None, clamp=True, detail=False):
        """F of one circle (radius clamped to rmax if clamp); BIG if inadmissible."""
        if clamp:
            R = min(R, self.rmax(xc, yc))
        if R <= 0:
            return BIG
        iv = self.intervals(xc, yc, R)
        if not iv:
            return BIG
        iv = [(a, b) for a, b in iv if self.admissible(xc, yc, R, a, b)]
        if not iv:
            return BIG
        M = len(iv)
        F, Ff, okm = self.bishop_batch([xc] * M, [yc] * M, [R] * M,
                                       [p[0] for p in iv], [p[1] for p in iv], N)
        self.n_eval += 1
        F = np.where(okm & np.isfinite(F), F, BIG)
        i = int(np.argmin(F))
        if detail:
            a, b = iv[i]
            xm = a + (b - a) * (np.arange(self.N if N is None else N) + 0.5) / (self.N if N is None else N)
            sa = (xc - xm) / R
            mmin = float(np.min(np.sqrt(1 - sa * sa) + sa * self.tphi / F[i]))
            return dict(F=float(F[i]), Ff=float(Ff[i]), xc=xc, yc=yc, R=R,
                        a=a, b=b, okm=bool(okm[i]), mmin=mmin)
        return float(F[i])

    # ------------------------------------------------------------- search
    def grid_search(self, nx=41, ny=41, nr=40, N=None, verbose=False):
        H, xt = self.H, self.xt
        Ls = H + self.Df
        x0 = -H - xt if self.Lb is None else -self.Lb - 0.5 * H
        x1 = xt + H
        xcs = np.linspace(x0, x1, nx)
        ycs = np.linspace(0.25 * H, H + 4.0 * Ls, ny)
        rows = []
        for xc in xcs:
            for yc in ycs:
                r0, r1 = self.rmin(xc, yc), self.rmax(xc, yc)
                if r1 <= r0 * (1 + 1e-9):
                    continue
                Rs = list(np.linspace(r0, r1, nr + 1)[1:])
                rt = math.hypot(xt - xc, yc)                  # through the toe
                if r0 < rt < r1:
                    Rs.append(rt)
                for R in Rs:
                    iv = self.intervals(xc, yc, R)
                    if not iv:
                        continue
                    for a, b in iv:
                        if self.admissible(xc, yc, R, a, b):
                            rows.append((xc, yc, R, a, b))
        rows = np.array(rows)
        F = np.empty(len(rows))
        okm = np.empty(len(rows), bool)
        B = 4000
        for i in range(0, len(rows), B):
            r = rows[i:i + B]
            F[i:i + B], _, okm[i:i + B] = self.bishop_batch(*r.T, N=N)
        self.n_grid_circles = len(rows)
        self.n_reject_m = int(np.sum(~okm & np.isfinite(F)))
        F = np.where(okm & np.isfinite(F), F, BIG)
        order = np.argsort(F)
        return rows, F, order

    def nelder_mead(self, p0, scale, tol=1e-9, maxit=4000, N=None):
        f = lambda p: self.evaluate(p[0], p[1], p[2], N=N)
        n = len(p0)
        P = [np.array(p0, float)]
        for i in range(n):
            q = np.array(p0, float)
            q[i] += scale[i]
            P.append(q)
        Fv = [f(p) for p in P]
        for it in range(maxit):
            idx = np.argsort(Fv)
            P = [P[i] for i in idx]
            Fv = [Fv[i] for i in idx]
            size = max(np.max(np.abs(P[i] - P[0])) for i in range(1, n + 1))
            if abs(Fv[-1] - Fv[0]) <= tol * abs(Fv[0]) and size < 1e-7 * self.H:
                break
            cen = np.mean(P[:-1], axis=0)
            xr = cen + (cen - P[-1]); fr = f(xr)
            if fr < Fv[0]:
                xe = cen + 2 * (cen - P[-1]); fe = f(xe)
                P[-1], Fv[-1] = (xe, fe) if fe < fr else (xr, fr)
            elif fr < Fv[-2]:
                P[-1], Fv[-1] = xr, fr
            else:
                xk = cen + 0.5 * (P[-1] - cen) if fr >= Fv[-1] else cen + 0.5 * (xr - cen)
                fk = f(xk)
                if fk < min(fr, Fv[-1]):
                    P[-1], Fv[-1] = xk, fk
                else:
                    for i in range(1, n + 1):
                        P[i] = P[0] + 0.5 * (P[i] - P[0]); Fv[i] = f(P[i])
        i = int(np.argmin(Fv))
        return P[i], Fv[i]

    def search(self, grid=(41, 41, 40), nstart=6, N=None, verbose=False):
        t0 = time.time()
        rows, F, order = self.grid_search(*grid, N=N)
        Fgrid = F[order[0]]
        # distinct starting points (separated in centre position)
        starts = []
        for i in order:
            if F[i] >= BIG:
                break
            p = rows[i, :3]
            if all(np.hypot(*(p[:2] - s[:2])) > 0.15 * self.H for s in starts):
                starts.append(p)
            if len(starts) >= nstart:
                break
        best = (None, BIG)
        for p in starts:
            sc = np.array([0.1, 0.1, 0.05]) * self.H
            q, fq = p, BIG
            for rep in range(4):            # restarts
                q, fq_new = self.nelder_mead(q, sc, N=N)
                if rep > 0 and abs(fq_new - fq) < 1e-10 * fq:
                    fq = fq_new
                    break
                fq = fq_new
                sc = sc * 0.2
            if fq < best[1]:
                best = (q, fq)
        q = best[0]
        d = self.evaluate(q[0], q[1], q[2], N=N, detail=True)
        d['Fgrid'] = Fgrid
        d['ngrid'] = self.n_grid_circles
        d['nrej_m'] = self.n_reject_m
        d['time'] = time.time() - t0
        return d

    # independent check for phi = 0: exact polygon area / centroid moment
    def phi0_exact(self, xc, yc, R, a, b, npts=200000):
        x = np.linspace(a, b, npts)
        x = np.unique(np.concatenate([x, [v for v in (0.0, self.xt) if a < v < b]]))
        top = self.yg(x)
        # polygon: ground from a to b, then arc back from b to a
        xs = np.concatenate([x, x[::-1]])
        ys = np.concatenate([top, (yc - np.sqrt(np.maximum(R * R - (x - xc) ** 2, 0)))[::-1]])
        x1, y1 = np.roll(xs, -1), np.roll(ys, -1)
        cr = xs * y1 - x1 * ys
        A = 0.5 * np.sum(cr)
        cx = np.sum((xs + x1) * cr) / (6 * A)
        th = math.asin((b - xc) / R) - math.asin((a - xc) / R)
        Larc = R * th
        return self.c * Larc * R / (self.gamma * abs(A) * (xc - cx))


def run(label, H, n, gamma, c, phi, Df=0.0, Lb=None, Lf=None, N=400, grid=(41, 41, 40), quiet=False):
    s = Slope(H, n, gamma, c, phi, Df, Lb, Lf, nslices=N)
    d = s.search(grid=grid)
    d['n'] = n
    ya = float(s.yg(d['a'])); yb = float(s.yg(d['b']))
    low = d['yc'] - d['R'] if d['a'] <= d['xc'] <= d['b'] else min(ya, yb)
    if not quiet:
        print("%-34s F=%.5f  Fell=%.4f  c=(%8.3f,%8.3f) R=%7.3f  entry=(%7.3f,%6.3f) exit=(%7.3f,%6.3f) "
              "low=%6.3f  grid F=%.4f  [%d circles, %d rej m<0.2, %.1fs]"
              % (label, d['F'], d['Ff'], d['xc'], d['yc'], d['R'], d['a'], ya, d['b'], yb, low,
                 d['Fgrid'], d['ngrid'], d['nrej_m'], d['time']))
        sys.stdout.flush()
    return s, d


def main():
    print("numpy", np.__version__, "| Bishop simplified, N=400 slices, grid 41x41 centres x 40 radii (+toe circle), "
          "then Nelder-Mead on (xc,yc,R) from the 6 best distinct centres; m_alpha<0.2 rejected\n")
    hdr = "%-34s %s" % ("case", "F_Bishop  F_Fellenius(same circle)  centre  R  entry  exit  lowest-point  grid-F")
    print(hdr)
    print("== Case 1: Griffiths & Lane 1999 Ex.1 (H=10, 2:1, gamma=20, c=10, phi=20, Df=0); B&M chart 1.380")
    for Lb in (None, 2.0, 1.5, 1.2, 1.0, 0.5, 0.25, 0.2, 0.1):
        lab = "no back wall" if Lb is None else "L_back=%.2fH" % Lb
        run("1 " + lab, 10, 2, 20, 10, 20, 0.0, None if Lb is None else Lb * 10)
    print("\n== Case 2: same, dimensionless (H=1, gamma=1, c=0.05, phi=20)")
    for Lb in (None, 2.0, 1.5, 1.2, 1.0, 0.5):
        lab = "no back wall" if Lb is None else "L_back=%.2fH" % Lb
        run("2 " + lab, 1, 2, 1, 0.05, 20, 0.0, Lb)
    print("\n== Case 3: ssnp006 / Plaxis (H=4.5, n=2, gamma=16, c=5, phi=20, Df=2); Verruijt Bishop 1.534")
    for Lb, Lf in ((None, None), (4.5, 4.5), (3, 6), (6, 3)):
        lab = "no walls" if Lb is None else "L_back=%g L_front=%g" % (Lb, Lf)
        run("3 " + lab, 4.5, 2, 16, 5, 20, 2.0, Lb, Lf)

    print("\n== Convergence: F at the critical circle vs number of slices N")
    for lab, args in (("case 1", (10, 2, 20, 10, 20, 0.0)), ("case 3", (4.5, 2, 16, 5, 20, 2.0))):
        s, d = run(lab, *args, quiet=True)
        print("  %s (m_alpha,min=%.3f): " % (lab, d['mmin']) + "  ".join(
            "N=%d:%.6f" % (N, s.evaluate(d['xc'], d['yc'], d['R'], N=N)) for N in (25, 50, 100, 200, 400, 800, 1600)))
        for N in (50, 1600):
            s2, d2 = run(lab, *args, N=N, quiet=True)
            print("    re-optimised with N=%d: F=%.6f" % (N, d2['F']))
    print("\n== Convergence: search resolution (grid min -> after Nelder-Mead)")
    for lab, args in (("case 1", (10, 2, 20, 10, 20, 0.0)), ("case 3", (4.5, 2, 16, 5, 20, 2.0))):
        for g in ((11, 11, 10), (21, 21, 20), (41, 41, 40), (81, 81, 80)):
            s, d = run(lab, *args, grid=g, quiet=True)
            print("  %s grid %-12s %6d circles: grid F=%.5f  -> NM F=%.6f  centre (%.4f, %.4f) R=%.4f"
                  % (lab, "x".join(map(str, g)), d['ngrid'], d['Fgrid'], d['F'], d['xc'], d['yc'], d['R']))

    print("\n== Check: phi=0, 2:1 slope (H=1, gamma=1, c=0.1), depth factor D=(H+Df)/H;"
          " Bishop must equal Fellenius and the exact moment c*L*R/(W*arm);"
          " Taylor/Fellenius D->inf: N=c/(gamma H F)=0.181 (Ns=5.52), centre above mid-slope")
    for D in (1, 1.5, 2, 3, 5, 10, 20, 50):
        s, d = run('', 1.0, 2, 1.0, 0.1, 0.0, D - 1.0, quiet=True)
        ex = s.phi0_exact(d['xc'], d['yc'], d['R'], d['a'], d['b'])
        print("  D=%-4g F=%.6f Fell=%.6f exact=%.6f  N=%.5f Ns=%.3f  centre (%.3f, %.3f) R=%.3f"
              % (D, d['F'], d['Ff'], ex, 0.1 / d['F'], d['F'] / 0.1, d['xc'], d['yc'], d['R']))


if __name__ == "__main__":
    main()
