#!/usr/bin/env python3
"""Solve squeal's frictional QEP band with SciPy and compare with squeal's own solve.

Reads an operator directory written by `squeal export` (Mc.mtx, Kc.mtx, FM.mtx, FK.mtx),
forms M~ = Mc - mu FM and K~ = Kc - mu FK (no damping: C = 0), and finds every mode in the
band with the same squared spectral transformation squeal uses when C = 0:

    (lambda^2 M~ + K~) u = 0   <=>   (K~ - s M~) u = 0,   s = -lambda^2,
    OP = (K~ - sigma M~)^-1 M~ (one real sparse LU per window, scipy.sparse.linalg.splu),
    scipy.sparse.linalg.eigs(OP, k, which='LM') (ARPACK, standard mode),
    s = sigma + 1/theta,  lambda = i sqrt(s).

Why not `eigs(K~, M=M~, sigma=...)`: SciPy's generalized mode requires M to be real
symmetric (ARPACK's B inner product), and M~ = Mc - mu FM is not; the shift-invert operator
is therefore passed as a LinearOperator in standard mode, exactly as squeal does.

Windows follow squeal's band driver (crates/squeal-core/src/qep/band.rs):
a window [lo, hi] Hz has sigma = ((2 pi lo)^2 + (2 pi hi)^2) / 2 and radius
R = 1.05 (b - a) / 2 + 0.01 (2 pi hi)^2; k starts at 24 and doubles until one converged
eigenvalue lies outside |s - sigma| > R (then every eigenvalue inside has been found);
past k = 400 the window is split in two. Backward errors as in squeal:
eta = ||Q(lambda) u|| / ((|lambda|^2 ||M~||_1 + ||K~||_1) ||u||).

Writes scipy.json (time_s, modes: freq_hz, re, im, backward_error) and, when given squeal's
`stability --json` output, prints a side-by-side comparison.
"""

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
import scipy
import scipy.io
import scipy.sparse as sp
import scipy.sparse.linalg as spla

TWO_PI = 2.0 * math.pi
REAL_ROOT_REL = 1e-10  # squeal's REAL_ROOT_REL: |Im lambda| <= this |lambda| is a real root


def load_operator(d: Path, mu: float):
    """M~, K~ (CSC) of the exported operator at mu."""
    rd = lambda name: sp.csc_matrix(scipy.io.mmread(str(d / name)))  # noqa: E731
    mc, kc, fm, fk = (rd(f) for f in ("Mc.mtx", "Kc.mtx", "FM.mtx", "FK.mtx"))
    if (d / "Cc.mtx").exists() or (d / "FC.mtx").exists():
        sys.exit("scipy_compare: the operator has damping (Cc/FC); only C = 0 is supported")
    return (mc - mu * fm).tocsc(), (kc - mu * fk).tocsc()


def backward_errors(m, k, lam, vecs):
    """squeal's backward error of each pair (1-norms of the matrices, 2-norms of vectors)."""
    mn = spla.norm(m, 1)
    kn = spla.norm(k, 1)
    mu_ = m @ vecs
    ku = k @ vecs
    r = ku + (lam**2)[None, :] * mu_
    num = np.linalg.norm(r, axis=0)
    den = (np.abs(lam) ** 2 * mn + kn) * np.linalg.norm(vecs, axis=0)
    return num / den


class Band:
    """squeal's band driver, on SciPy's splu + eigs."""

    def __init__(self, m, k, tol, max_nev=400, nev0=24, radius_factor=1.05,
                 margin_rel=0.01, max_depth=10, verbose=True):
        self.m, self.k, self.tol = m, k, tol
        self.n = m.shape[0]
        self.cap = max(1, min(max_nev, self.n - 2))
        self.nev0 = nev0
        self.radius_factor, self.margin_rel, self.max_depth = radius_factor, margin_rel, max_depth
        self.lam, self.vecs = [], []
        self.windows = self.factorizations = self.applications = 0
        self.factor_s = 0.0
        self.notes = []
        self.verbose = verbose

    def window(self, lo, hi, depth, nev0):
        a, b = (TWO_PI * lo) ** 2, (TWO_PI * hi) ** 2
        sigma = 0.5 * (a + b)
        radius = self.radius_factor * 0.5 * (b - a) + self.margin_rel * (TWO_PI * hi) ** 2
        t0 = time.perf_counter()
        lu = spla.splu((self.k - sigma * self.m).tocsc())
        self.factor_s += time.perf_counter() - t0
        self.factorizations += 1
        m = self.m
        count = [0]

        def matvec(x):
            count[0] += 1
            x = np.asarray(x).reshape(-1)
            mx = m @ x
            if np.iscomplexobj(mx):
                return lu.solve(np.ascontiguousarray(mx.real)) + 1j * lu.solve(
                    np.ascontiguousarray(mx.imag))
            return lu.solve(mx)

        op = spla.LinearOperator((self.n, self.n), matvec=matvec, dtype=float)
        nev = min(max(nev0, 1), self.cap)
        while True:
            try:
                theta, z = spla.eigs(op, k=nev, which="LM", tol=self.tol, maxiter=300 * self.n)
                converged = True
            except spla.ArpackNoConvergence as e:
                theta, z = e.eigenvalues, e.eigenvectors
                converged = False
            s = sigma + 1.0 / theta
            reach = np.max(np.abs(s - sigma)) if len(s) else 0.0
            if not converged:
                self.notes.append(f"window [{lo:.6g}, {hi:.6g}] Hz: {len(theta)}/{nev} converged")
                break
            if reach > radius:
                break
            if nev >= self.cap:
                if depth < self.max_depth:
                    self.applications += count[0]
                    mid = 0.5 * (lo + hi)
                    nxt = min(max(nev // 2, nev0), self.cap)
                    self.notes.append(f"window [{lo:.6g}, {hi:.6g}] Hz split")
                    del lu
                    self.window(lo, mid, depth + 1, nxt)
                    self.window(mid, hi, depth + 1, nxt)
                    return
                self.notes.append(f"window [{lo:.6g}, {hi:.6g}] Hz not covered")
                break
            nev = min(2 * nev, self.cap)
        self.applications += count[0]
        self.windows += 1
        if self.verbose:
            print(f"  scipy window [{lo:.0f}, {hi:.0f}] Hz: k = {nev}, {count[0]} OP applications",
                  file=sys.stderr)
        lam = 1j * np.sqrt(s.astype(complex))  # principal root: Im(lambda) >= 0
        keep_new(self, lo, hi, ((l, lambda j=j: z[:, j]) for j, l in enumerate(lam)))


def keep_new(band, lo, hi, pairs):
    """Appends to `band.lam` and `band.vecs` the pairs `(lambda, vector getter)` of the
    window [lo, hi] Hz that lie in it (Im(lambda) > 0) and that no earlier window found
    (one earlier match per pair, to max(1e-8, 100 tol) relative)."""
    slack = 1e-8 * hi
    before = len(band.lam)
    matched = [False] * before
    for l, vector in pairs:
        if not np.isfinite(l) or l.imag <= 0.0:
            continue
        f = l.imag / TWO_PI
        if f < lo - slack or f > hi + slack:
            continue
        tol = max(1e-8 * abs(l), 100.0 * band.tol * abs(l))
        dup = next((p for p in range(before)
                    if not matched[p] and abs(band.lam[p] - l) <= tol), None)
        if dup is not None:
            matched[dup] = True
            continue
        band.lam.append(l)
        band.vecs.append(vector())


def band_modes(band, m, k, fmin, fmax):
    """The modes `band` found in [fmin, fmax] Hz by frequency, real roots left out, with
    their backward errors: `(lambda, eta)`."""
    lam = np.array(band.lam, dtype=complex)
    vecs = np.array(band.vecs).T if band.vecs else np.zeros((m.shape[0], 0), complex)
    keep = sorted((lam[i].imag / TWO_PI, i) for i in range(len(lam))
                  if abs(lam[i].imag) > REAL_ROOT_REL * abs(lam[i])
                  and fmin * (1 - 1e-12) <= lam[i].imag / TWO_PI <= fmax * (1 + 1e-12))
    idx = [i for _, i in keep]
    lam, vecs = lam[idx], vecs[:, idx]
    eta = backward_errors(m, k, lam, vecs) if len(lam) else np.zeros(0)
    return lam, eta


def solve_band(m, k, fmin, fmax, tol):
    band = Band(m, k, tol)
    t0 = time.perf_counter()
    band.window(fmin, fmax, 0, band.nev0)
    solve_s = time.perf_counter() - t0
    lam, eta = band_modes(band, m, k, fmin, fmax)
    return lam, eta, solve_s, band


def compare(squeal, modes):
    """Matches each squeal mode to the nearest SciPy mode (in lambda)."""
    sq = np.array([complex(md["re"], md["im"]) for md in squeal["modes"]])
    sc = np.array([complex(md["re"], md["im"]) for md in modes])
    out = {"squeal_modes": len(sq), "scipy_modes": len(sc), "unmatched_squeal": 0,
           "unmatched_scipy": 0, "max_rel_freq_diff": 0.0, "max_abs_re_diff": 0.0,
           "max_abs_dvr_diff": 0.0, "unstable_squeal": 0, "unstable_scipy": 0}
    if len(sq) == 0 or len(sc) == 0:
        return out
    used = set()
    for l in sq:
        j = int(np.argmin(np.abs(sc - l)))
        if abs(sc[j] - l) > 1e-4 * abs(l):
            out["unmatched_squeal"] += 1
            continue
        used.add(j)
        out["max_rel_freq_diff"] = max(out["max_rel_freq_diff"], abs(sc[j].imag - l.imag) / l.imag)
        out["max_abs_re_diff"] = max(out["max_abs_re_diff"], abs(sc[j].real - l.real))
        out["max_abs_dvr_diff"] = max(out["max_abs_dvr_diff"],
                                     abs(sc[j].real / sc[j].imag - l.real / l.imag))
    out["unmatched_scipy"] = len(sc) - len(used)
    # same instability test as squeal's default unstable_tol (relative Re > tol |lambda|)
    tol = squeal.get("unstable_tol", 1e-6)
    out["unstable_squeal"] = sum(1 for md in squeal["modes"] if md["unstable"])
    out["unstable_scipy"] = int(np.sum(sc.real > tol * np.abs(sc)))
    return out


def parse_args(ap, peer_json):
    """Adds the arguments both comparisons take to `ap` and parses them; returns the
    arguments, squeal's output (or None) and the band: `--band`, else squeal's, else 0-5 kHz."""
    ap.add_argument("operator", type=Path, help="operator directory (squeal export --out DIR)")
    ap.add_argument("--mu", type=float, required=True)
    ap.add_argument("--band", default=None,
                    help="FMIN:FMAX in Hz (default: squeal's band from --squeal-json, else 0:5000)")
    ap.add_argument("--tol", type=float, default=1e-12)
    ap.add_argument("--squeal-json", type=Path, help="`squeal stability --json` output")
    ap.add_argument("--out", type=Path, default=None, help=f"{peer_json} path")
    args = ap.parse_args()
    sq = json.loads(args.squeal_json.read_text()) if args.squeal_json else None
    if args.band:
        fmin, fmax = (float(x) for x in args.band.split(":"))
    else:
        fmin, fmax = sq["band_hz"] if sq else (0.0, 5000.0)
    return args, sq, fmin, fmax


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    args, sq, fmin, fmax = parse_args(ap, "scipy.json")

    t0 = time.perf_counter()
    m, k = load_operator(args.operator, args.mu)
    load_s = time.perf_counter() - t0
    print(f"SciPy {scipy.__version__}, NumPy {np.__version__}: operator n = {m.shape[0]}, "
          f"nnz(M~) = {m.nnz}, nnz(K~) = {k.nnz}, read in {load_s:.2f}s", file=sys.stderr)
    lam, eta, solve_s, band = solve_band(m, k, fmin, fmax, args.tol)
    report = {
        "solver": "scipy.sparse.linalg.eigs (ARPACK) on splu(K~ - sigma M~)^-1 M~",
        "scipy": scipy.__version__, "numpy": np.__version__,
        "factor_s": band.factor_s, "op_applications": band.applications,
    }
    extra = [("total time incl. reading (s)", f"{sq['time_s']:.2f}" if sq else "",
              f"{solve_s + load_s:.2f}")]
    write_and_compare("SciPy", "SciPy eigs", args, (fmin, fmax), m.shape[0], lam, eta, solve_s,
                      load_s, band, report, sq, extra, args.out or (args.operator / "scipy.json"))


def write_and_compare(peer, column, args, band_hz, dofs, lam, eta, solve_s, load_s, band,
                      report, sq, extra_rows, out):
    """Completes `report` with the modes and the run's figures, writes it to `out` and,
    given squeal's output `sq`, adds the comparison and prints the side-by-side table
    (`extra_rows` after the solve time) with the speed ratio and the largest differences."""
    modes = [{"freq_hz": l.imag / TWO_PI, "re": l.real, "im": l.imag,
              "dvr": l.real / l.imag, "backward_error": float(e)} for l, e in zip(lam, eta)]
    report.update({
        "mu": args.mu, "band_hz": list(band_hz), "tol": args.tol, "dofs": dofs,
        "time_s": solve_s, "load_s": load_s,
        "windows": band.windows, "factorizations": band.factorizations, "notes": band.notes,
        "max_backward_error": float(eta.max()) if len(eta) else 0.0,
        "modes": modes,
    })
    out.write_text(json.dumps(report, indent=1))
    print(f"wrote {out}: {len(modes)} modes in {solve_s:.2f}s", file=sys.stderr)
    if not sq:
        return
    c = compare(sq, modes)
    report["comparison"] = c
    out.write_text(json.dumps(report, indent=1))
    rows = [("solve time (s)", f"{sq['solve_time_s']:.2f}", f"{solve_s:.2f}")] + extra_rows + [
        ("modes in band", str(len(sq["modes"])), str(len(modes))),
        ("unstable modes", str(c["unstable_squeal"]), str(c["unstable_scipy"])),
        ("factorizations", str(sq.get("factorizations", "?")), str(band.factorizations)),
        ("worst backward error", f"{sq['max_backward_error']:.2e}",
         f"{report['max_backward_error']:.2e}"),
    ]
    w = max(len(r[0]) for r in rows)
    print(f"\n{'mu = ' + str(args.mu) + ', ' + str(dofs) + ' DOFs':<{w}}  "
          f"{'squeal arpack':>14}  {column:>14}")
    for name, a, b in rows:
        print(f"{name:<{w}}  {a:>14}  {b:>14}")
    if "settings" in report:
        print(f"{peer} settings: {report['settings']}")
    print(f"speed ratio {peer} / squeal (solve): {solve_s / max(sq['solve_time_s'], 1e-9):.2f}")
    print(f"matched modes: {c['squeal_modes'] - c['unmatched_squeal']} "
          f"(unmatched: squeal {c['unmatched_squeal']}, {peer} {c['unmatched_scipy']})")
    print(f"max relative frequency difference: {c['max_rel_freq_diff']:.2e}")
    print(f"max |Re(lambda)| difference: {c['max_abs_re_diff']:.2e} 1/s "
          f"(max |DvR| difference {c['max_abs_dvr_diff']:.2e})")

if __name__ == "__main__":
    main()
