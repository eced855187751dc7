#!/usr/bin/env python3
"""Parametric test operators and their dense SciPy references, built with numpy/scipy only
(independent of squeal's assembler), and the MAT-file fixtures of squeal-io.

Subcommands
-----------
``operator OUT [--nx NX --ny NY] [--reference]``
    A 2-D lattice of point masses (2 DOFs per node, left edge clamped) written as an
    operator directory for ``squeal_io::ParametricOperator`` (docs/operators.md), the
    parameter ``W`` being a rotation speed (rad/s):

    - ``M``: lumped masses;
    - ``C = D1 + (1/W) DR + W DG``: Rayleigh damping ``D1``, a symmetric damping ``DR``
      and a gyroscopic (skew) ``DG``;
    - ``K = K1 + KR + W^2 KGeo``: lattice springs, a symmetric stiffness ``KR``, a
      centrifugal stiffening ``KGeo``;
    - ``FK``: a circulatory (non-symmetric) friction part on a top-edge contact patch
      (tangential force proportional to the normal displacement), ``K~ = K - mu FK``.

    Components are written as Matrix Market files (``K1.mtx``, ``KGeo.mtx``, ...) and as
    one MAT-file ``components.mat``; ``operator.toml`` reads ``M``, ``K1``, ``D1`` and
    ``FK`` from ``.mtx`` and the others from the MAT-file. ``fingerprint.json`` holds the
    sum of absolute entries of every component (to detect a changed generator).
    With ``--reference``, ``reference.json``: every eigenvalue of
    ``(lambda^2 M~ + lambda C~ + K~) x = 0`` in the band at each case (W, mu), by a dense
    eigenvalue solve of the inverted companion form (scipy.linalg.eigvals; the
    low-frequency band is then the well-resolved end of the spectrum), each refined by
    Newton steps on ``det Q`` with sparse LU factors (two-sided Rayleigh quotient), kept as
    squeal keeps modes (``Im > 0``, frequency in the band, ``-Re <= Im``).

``brake OUT [--nx NX --ny NY] [--reference] [--tune] [--no-modal]``
    A brake-like operator on the same lattice whose SYMMETRIC stiffness part is indefinite
    at high speed and which has a weakly unstable mode, the kind of model industrial
    brake codes export (``K(W) = K1 + KR + W^2 KGeo``, ``C(W) = D1 + DR/W + W DG + DN``):

    - ``KR``: a circulatory stiffness as large as a quarter of ``K1`` (norm), the
      similarity ``T K1 T^-1 - K1`` with ``T = I + beta E``, ``E`` coupling each node's
      x force to its y displacement (``E^2 = 0``, so ``T^-1 = I - beta E``, and ``T``
      commutes with the lumped mass): ``K1 + KR`` keeps the real spectrum of ``K1``
      while its symmetric part is nearly indefinite;
    - ``D1``, ``DR``, ``DG``, ``DN`` seen through the same similarity (``T D T^-1``: a
      non-symmetric damping and a gyroscopic part that is no longer skew), so that at
      ``mu = 0`` the operator is ``T Q0(lambda) T^-1`` and has the spectrum of the
      symmetric lattice ``Q0`` (a circulatory stiffness next to a skew gyroscopic part
      would otherwise flutter on its own);
    - ``KGeo``: a NEGATIVE geometric (softening) stiffness, the same on both DOFs of a
      node (so it commutes with ``T`` too): the symmetric part of ``K`` is positive
      definite at low ``W`` and indefinite above about ``W = 40``, while the undamped
      operator's modes stay real up to ``W = 100``;
    - ``DN``: a negative damping on the x DOFs of the contact patch (a friction
      characteristic falling with the sliding speed), scaled so that ONE mode has
      ``DvR = WEAK_DVR`` at ``(W, mu) = WEAK_AT``: unstable with a growth rate far below
      any DvR threshold, yet certain (its error bound is orders of magnitude smaller);
    - ``M``, ``FK`` and, before the similarity, ``D1``, ``DR``, ``DG`` as for ``operator``.

    ``operator.toml`` also names the real-mode pair ``[modal] M = ["M"], K = ["K1"]``
    (the undamped, non-rotating, friction-free system); ``--no-modal`` leaves it out. ``--tune`` finds the scale of
    ``DN`` again (a dense eigenvalue solve and Newton steps on the weak mode, about a
    minute) and prints it; the operator is written with the committed ``DN_SCALE``.
    With ``--reference``, ``reference.json`` as for ``operator``, at ``BRAKE_CASES``.

``mat-fixtures OUT``
    Small MAT-files written by ``scipy.io.savemat`` (compressed and not) with the same
    matrices as Matrix Market files, plus files the reader must refuse.

Run: ``python3 benches/parametric_operator.py operator /tmp/op --reference``.
"""

import argparse
import json
import os
import sys

import numpy as np
import scipy.io
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

CASES = [(5.0, 0.0), (5.0, 0.6), (20.0, 0.3), (20.0, 0.8)]


def lattice(nx, ny):
    """Components of the lattice operator (module docs), as CSC matrices."""
    nodes = nx * ny
    idx = lambda i, j: i * ny + j  # node (i, j): column i (x), row j (y)
    dof = lambda node, d: 2 * node + d
    rows, cols, vals = [], [], []

    def spring(a, b, direction, k):
        # a spring between nodes a and b along the unit vector `direction`
        e = np.asarray(direction, float)
        e = e / np.linalg.norm(e)
        kk = k * np.outer(e, e)
        for p in range(2):
            for q in range(2):
                for (r, c, s) in [(a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)]:
                    rows.append(dof(r, p))
                    cols.append(dof(c, q))
                    vals.append(s * kk[p, q])

    for i in range(nx):
        for j in range(ny):
            a = idx(i, j)
            base = 2.0e5 * (1.0 + 0.25 * np.sin(0.37 * i + 0.91 * j))
            if i + 1 < nx:
                spring(a, idx(i + 1, j), (1, 0), base)
            if j + 1 < ny:
                spring(a, idx(i, j + 1), (0, 1), 1.3 * base)
            if i + 1 < nx and j + 1 < ny:
                spring(a, idx(i + 1, j + 1), (1, 1), 0.4 * base)
            if i + 1 < nx and j > 0:
                spring(a, idx(i + 1, j - 1), (1, -1), 0.35 * base)
    n_all = 2 * nodes
    k1 = sp.coo_matrix((vals, (rows, cols)), shape=(n_all, n_all)).tocsc()
    mass = np.array(
        [1e-3 * (1.0 + 0.3 * np.sin(0.7 * a)) for a in range(nodes) for _ in range(2)]
    )
    m = sp.diags(mass).tocsc()
    # geometric stiffening: the same pattern as the springs, radial weight
    kgeo = sp.diags(
        [2.0 * (1.0 + (a // ny) / nx) for a in range(nodes) for _ in range(2)]
    ).tocsc()
    kr = sp.diags(
        [3.0e3 * (1.0 + 0.5 * np.cos(0.3 * a)) for a in range(nodes) for _ in range(2)]
    ).tocsc()
    # gyroscopic: Coriolis coupling x <-> y at every node, skew
    g = [2e-3 * mass[2 * a] / 1e-3 for a in range(nodes)]
    dg = sp.coo_matrix(
        (g + [-v for v in g],
         ([2 * a for a in range(nodes)] + [2 * a + 1 for a in range(nodes)],
          [2 * a + 1 for a in range(nodes)] + [2 * a for a in range(nodes)])),
        shape=(n_all, n_all),
    ).tocsc()
    d1 = (2.0 * m + 2e-7 * k1).tocsc()
    dr = sp.diags(
        [0.02 * (1.0 + 0.4 * np.sin(0.13 * a)) for a in range(nodes) for _ in range(2)]
    ).tocsc()
    # friction: top edge contact patch, F_x = mu kn u_y (circulatory)
    patch = [idx(i, ny - 1) for i in range(nx // 3, nx - 1)]
    kn = 6.0e4
    fk = sp.coo_matrix(
        ([kn] * len(patch), ([dof(a, 0) for a in patch], [dof(a, 1) for a in patch])),
        shape=(n_all, n_all),
    ).tocsc()
    # clamp the left edge (column i = 0)
    free = np.array([d for d in range(n_all) if (d // 2) // ny != 0])
    cut = lambda a: a[free][:, free].tocsc()
    return {
        "M": cut(m),
        "K1": cut(k1),
        "KR": cut(kr),
        "KGeo": cut(kgeo),
        "D1": cut(d1),
        "DR": cut(dr),
        "DG": cut(dg),
        "FK": cut(fk),
    }


# The brake operator (module docs, ``brake``).
BETA = 0.5                 # strength of the circulatory similarity T = I + beta E
GEO = 1.6e-3               # negative geometric stiffness per node (N/m per (rad/s)^2)
WEAK_AT = (60.0, 0.0)      # (W, mu) where one mode is weakly unstable
WEAK_DVR = 4e-8            # its divergence rate there
DN_SCALE = 0.057984352218248374  # scale of DN, found by --tune: 172.881 Hz, DvR 4.0e-8
BRAKE_CASES = [(5.0, 0.0), (60.0, 0.0), (60.0, 0.3), (100.0, 0.6)]


def brake(nx, ny, dn_scale=None):
    """Components of the brake operator (module docs), as CSC matrices."""
    comp = lattice(nx, ny)
    k1 = comp["K1"]
    n = k1.shape[0]
    # free DOFs come in node pairs (x, y) = (2p, 2p + 1); node of pair p
    nodes = [a for a in range(nx * ny) if a // ny != 0]
    e = sp.coo_matrix(
        (np.ones(n // 2), (np.arange(0, n, 2), np.arange(1, n, 2))), shape=(n, n)
    ).tocsc()
    t, t_inv = sp.eye(n) + BETA * e, sp.eye(n) - BETA * e

    def similar(x):
        y = (t @ x @ t_inv).tocsc()
        y.eliminate_zeros()
        return y

    comp["KR"] = (similar(k1) - k1).tocsc()
    comp["KR"].eliminate_zeros()
    comp["KGeo"] = sp.diags(
        [-GEO * (1.0 + (a // ny) / nx) for a in nodes for _ in range(2)]
    ).tocsc()
    patch = {a for a in range(nx * ny) if a % ny == ny - 1 and nx // 3 <= a // ny < nx - 1}
    xs = [2 * p for p, a in enumerate(nodes) if a in patch]
    dn = sp.coo_matrix((-np.ones(len(xs)), (xs, xs)), shape=(n, n)).tocsc()
    comp["DN"] = (DN_SCALE if dn_scale is None else dn_scale) * dn
    # the damping and gyroscopic parts seen through the same similarity: at mu = 0 the
    # operator is T Q0(lambda) T^-1, with the spectrum of the symmetric lattice Q0
    for name in ["D1", "DR", "DG", "DN"]:
        comp[name] = similar(comp[name])
    return comp


def assemble_brake(comp, w, mu):
    m = comp["M"]
    c = comp["D1"] + comp["DR"] / w + w * comp["DG"] + comp["DN"]
    k = comp["K1"] + comp["KR"] + w * w * comp["KGeo"] - mu * comp["FK"]
    return m.tocsc(), c.tocsc(), k.tocsc()


def band_modes(m, c, k, fmax):
    """Every eigenvalue in the band, dense (inverted companion form), unrefined."""
    n = m.shape[0]
    kd = k.toarray()
    a = np.zeros((2 * n, 2 * n))
    a[:n, :n] = -scipy.linalg.solve(kd, c.toarray())
    a[:n, n:] = -scipy.linalg.solve(kd, m.toarray())
    a[n:, :n] = np.eye(n)
    del kd
    nu = scipy.linalg.eigvals(a, overwrite_a=True, check_finite=False)
    return band_of([1.0 / v for v in nu if v != 0], fmax)


def two_sided(m, c, k, lam):
    """Right and left eigenvectors at an (accurate) eigenvalue, by inverse iteration."""
    n = m.shape[0]
    q = (lam * lam * m + lam * c + k).tocsc().astype(complex)
    lu = spla.splu(q)
    rng = np.random.default_rng(11)
    x = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    y = x.copy()
    for _ in range(3):
        x = lu.solve(x)
        x /= np.linalg.norm(x)
        y = lu.solve(y, trans="H")
        y /= np.linalg.norm(y)
    return x, y


def tune(nx, ny, fmax):
    """The scale of DN that gives one mode DvR = WEAK_DVR at WEAK_AT: first-order
    sensitivities of every band mode to the scale pick the first mode to cross, then
    Newton steps on that mode alone."""
    comp = brake(nx, ny, dn_scale=0.0)
    dn1 = brake(nx, ny, dn_scale=1.0)["DN"]
    w, mu = WEAK_AT
    m, c0, k = assemble_brake(comp, w, mu)
    lams = [refine(m, c0, k, l) for l in band_modes(m, c0, k, fmax * 1.05)]
    lams = band_of(lams, fmax)
    best = None
    for lam in lams:
        x, y = two_sided(m, c0, k, lam)
        d = -np.vdot(y, lam * (dn1 @ x)) / np.vdot(y, (2 * lam * m + c0) @ x)
        if lam.real < 0 and d.real > 0:
            s = -lam.real / d.real
            print(f"  {lam.imag / 2 / np.pi:8.2f} Hz: DvR {lam.real / lam.imag:+.3e}, "
                  f"crosses at scale ~{s:.4g}", file=sys.stderr)
            if best is None or s < best[0]:
                best = (s, lam)
    if best is None:
        raise SystemExit("tune: no stable mode is destabilized by DN")
    scale, lam = best
    for _ in range(30):
        c = c0 + scale * dn1
        lam = refine(m, c, k, lam, steps=6)
        x, y = two_sided(m, c, k, lam)
        d = -np.vdot(y, lam * (dn1 @ x)) / np.vdot(y, (2 * lam * m + c) @ x)
        # target Re = WEAK_DVR Im; d(Re - WEAK_DVR Im)/ds
        f = lam.real - WEAK_DVR * lam.imag
        step = f / (d.real - WEAK_DVR * d.imag)
        scale -= step
        if abs(step) <= 1e-14 * abs(scale):
            break
    lam = refine(m, c0 + scale * dn1, k, lam, steps=6)
    print(f"DN_SCALE = {float(scale)!r}  # {lam.imag / 2 / np.pi:.3f} Hz, "
          f"DvR {lam.real / lam.imag:.4e} at W = {w}, mu = {mu}")
    return scale


def assemble(comp, w, mu):
    m = comp["M"]
    c = comp["D1"] + comp["DR"] / w + w * comp["DG"]
    k = comp["K1"] + comp["KR"] + w * w * comp["KGeo"] - mu * comp["FK"]
    return m.tocsc(), c.tocsc(), k.tocsc()


def band_of(lams, fmax):
    out = []
    for l in lams:
        if not (np.isfinite(l.real) and np.isfinite(l.imag)):
            continue
        if l.imag <= 1e-10 * abs(l) or -l.real > l.imag:
            continue
        if l.imag / (2 * np.pi) <= fmax * (1 + 1e-12):
            out.append(l)
    return sorted(out, key=lambda z: (z.imag, z.real))


def refine(m, c, k, lam, steps=3):
    """Newton on det Q: x, y from inverse iteration with a sparse LU at lam, then the
    two-sided Rayleigh quotient correction."""
    n = m.shape[0]
    rng = np.random.default_rng(7)
    for _ in range(steps):
        q = (lam * lam * m + lam * c + k).tocsc().astype(complex)
        try:
            lu = spla.splu(q)
        except RuntimeError:
            return lam  # exactly singular: lam is an eigenvalue to round-off
        x = rng.standard_normal(n) + 1j * rng.standard_normal(n)
        y = x.copy()
        for _ in range(2):
            x = lu.solve(x)
            x /= np.linalg.norm(x)
            y = lu.solve(y, trans="H")
            y /= np.linalg.norm(y)
        num = np.vdot(y, q @ x)
        den = np.vdot(y, (2 * lam * m + c) @ x)
        if den == 0:
            return lam
        step = num / den
        lam = lam - step
        if abs(step) <= 1e-15 * abs(lam):
            break
    return lam


def reference(comp, fmax, which, assemble=assemble):
    cases = []
    for (w, mu) in which:
        m, c, k = assemble(comp, w, mu)
        n = m.shape[0]
        # inverted companion: nu = 1/lambda, [[-K^-1 C, -K^-1 M], [I, 0]]
        kd = k.toarray()
        kinv_c = scipy.linalg.solve(kd, c.toarray())
        kinv_m = scipy.linalg.solve(kd, m.toarray())
        a = np.zeros((2 * n, 2 * n))
        a[:n, :n] = -kinv_c
        a[:n, n:] = -kinv_m
        a[n:, :n] = np.eye(n)
        del kinv_c, kinv_m, kd
        nu = scipy.linalg.eigvals(a, overwrite_a=True, check_finite=False)
        lams = np.array([1.0 / v for v in nu if v != 0])
        band = band_of(lams, fmax * 1.05)
        refined = band_of([refine(m, c, k, l) for l in band], fmax)
        unstable = sum(1 for l in refined if l.real > 1e-8 * abs(l))
        print(f"W = {w}, mu = {mu}: {len(refined)} modes in 0-{fmax} Hz, "
              f"{unstable} unstable", file=sys.stderr)
        cases.append({
            "W": w,
            "mu": mu,
            "fmax_hz": fmax,
            "unstable": unstable,
            "eigenvalues": [[l.real, l.imag] for l in refined],
        })
    return cases


def write_operator(out, nx, ny, with_reference, fmax, which=CASES):
    os.makedirs(out, exist_ok=True)
    comp = lattice(nx, ny)
    n = comp["M"].shape[0]
    in_mtx = ["M", "K1", "D1", "FK"]
    for name in in_mtx:
        scipy.io.mmwrite(os.path.join(out, name + ".mtx"), comp[name], precision=17)
    scipy.io.savemat(
        os.path.join(out, "components.mat"),
        {k: v for k, v in comp.items() if k not in in_mtx},
        do_compression=True,
    )
    toml = f"""# Parametric test operator written by benches/parametric_operator.py
# ({nx} x {ny} lattice, {n} DOFs); see docs/operators.md.
format = "squeal-parametric-operator"
version = 1
parameter = "W"
range = [1.0, 100.0]
mat = "components.mat"
M = ["M"]
C = [{{ matrix = "D1" }}, {{ matrix = "DR", coeff = "1/W" }}, {{ matrix = "DG", coeff = "W" }}]
K = ["K1", "KR", {{ matrix = "KGeo", coeff = "W^2" }}]
FK = ["FK"]
"""
    with open(os.path.join(out, "operator.toml"), "w") as f:
        f.write(toml)
    fp = {k: float(abs(v).sum()) for k, v in comp.items()}
    with open(os.path.join(out, "fingerprint.json"), "w") as f:
        json.dump({"dofs": n, "abs_sum": fp}, f, indent=1, sort_keys=True)
    if with_reference:
        ref = {
            "source": "benches/parametric_operator.py: scipy.linalg.eigvals of the inverted "
                      "companion form, Newton-refined with sparse LU (two-sided Rayleigh "
                      "quotient)",
            "dofs": n,
            "lattice": [nx, ny],
            "parameter": "W",
            "fingerprint": fp,
            "cases": reference(comp, fmax, which),
        }
        with open(os.path.join(out, "reference.json"), "w") as f:
            json.dump(ref, f, indent=1)
    print(f"{out}: {n} DOFs", file=sys.stderr)


def write_brake(out, nx, ny, with_reference, fmax, which=BRAKE_CASES, modal=True):
    os.makedirs(out, exist_ok=True)
    comp = brake(nx, ny)
    n = comp["M"].shape[0]
    in_mtx = ["M", "K1", "D1", "FK"]
    for name in in_mtx:
        scipy.io.mmwrite(os.path.join(out, name + ".mtx"), comp[name], precision=17)
    scipy.io.savemat(
        os.path.join(out, "components.mat"),
        {k: v for k, v in comp.items() if k not in in_mtx},
        do_compression=True,
    )
    w, mu = WEAK_AT
    toml = f"""# Brake-like parametric test operator written by benches/parametric_operator.py
# ({nx} x {ny} lattice, {n} DOFs): circulatory KR, negative geometric stiffness KGeo
# (the symmetric part of K is indefinite above about W = 40), a negative damping DN
# that leaves one mode weakly unstable (DvR {WEAK_DVR:g} at W = {w:g}, mu = {mu:g}).
format = "squeal-parametric-operator"
version = 1
parameter = "W"
range = [1.0, 100.0]
mat = "components.mat"
M = ["M"]
C = [{{ matrix = "D1" }}, {{ matrix = "DR", coeff = "1/W" }}, {{ matrix = "DG", coeff = "W" }}, "DN"]
K = ["K1", "KR", {{ matrix = "KGeo", coeff = "W^2" }}]
FK = ["FK"]
"""
    if modal:
        toml += """
# the real-mode pair: the undamped, non-rotating, friction-free system
[modal]
M = ["M"]
K = ["K1"]
"""
    with open(os.path.join(out, "operator.toml"), "w") as f:
        f.write(toml)
    fp = {k: float(abs(v).sum()) for k, v in comp.items()}
    with open(os.path.join(out, "fingerprint.json"), "w") as f:
        json.dump({"dofs": n, "abs_sum": fp}, f, indent=1, sort_keys=True)
    if with_reference:
        ref = {
            "source": "benches/parametric_operator.py brake: scipy.linalg.eigvals of the "
                      "inverted companion form, Newton-refined with sparse LU (two-sided "
                      "Rayleigh quotient)",
            "dofs": n,
            "lattice": [nx, ny],
            "parameter": "W",
            "fingerprint": fp,
            "weak_mode": {"W": w, "mu": mu, "dvr": WEAK_DVR},
            "cases": reference(comp, fmax, which, assemble=assemble_brake),
        }
        with open(os.path.join(out, "reference.json"), "w") as f:
            json.dump(ref, f, indent=1)
    print(f"{out}: {n} DOFs", file=sys.stderr)


def mat_fixtures(out):
    os.makedirs(out, exist_ok=True)
    a = sp.csc_matrix(np.array([
        [4.0, 0.0, -1.5, 0.0],
        [0.0, 0.0, 0.0, 2.25e-9],
        [1e12, 0.0, 3.0, 0.0],
    ]))
    b = np.array([[1.0, -2.0], [0.5, 0.0], [3.25, 7.0e-3]])
    ints = np.array([[1, 0, -3], [0, 5, 0]], dtype=np.int32)
    single = np.array([[1.5, -0.25]], dtype=np.float32)
    big = sp.random(60, 45, density=0.08, random_state=np.random.RandomState(3),
                    format="csc")
    empty = sp.csc_matrix((5, 3))
    mats = {"A": a, "B": b, "I32": ints, "S": single, "R": big, "E": empty}
    for comp in (False, True):
        scipy.io.savemat(os.path.join(out, f"fixtures{'_z' if comp else ''}.mat"), mats,
                         do_compression=comp)
    for name, v in mats.items():
        # float64 text: SciPy pads float32 values written at precision 17 with NULs
        scipy.io.mmwrite(os.path.join(out, name + ".mtx"),
                         sp.coo_matrix(v).astype(np.float64), precision=17)
    scipy.io.savemat(os.path.join(out, "refused.mat"), {
        "Z": np.array([[1 + 2j, 0]]),
        "Zs": sp.csc_matrix(np.array([[0, 1j]])),
        "cell": np.array([[np.array([1.0]), np.array([2.0, 3.0])]], dtype=object),
        "txt": "hello",
        "cube": np.zeros((2, 2, 2)),
        "nan": np.array([[1.0, np.nan]]),
    })
    print(f"{out}: fixtures written", file=sys.stderr)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    o = sub.add_parser("operator")
    o.add_argument("out")
    o.add_argument("--nx", type=int, default=50)
    o.add_argument("--ny", type=int, default=41)
    o.add_argument("--fmax", type=float, default=1500.0)
    o.add_argument("--reference", action="store_true")
    o.add_argument("--cases", default=None,
                   help="W:mu pairs of the reference, comma separated (default: "
                        + ",".join(f"{w:g}:{m:g}" for w, m in CASES) + ")")
    b = sub.add_parser("brake")
    b.add_argument("out")
    b.add_argument("--nx", type=int, default=50)
    b.add_argument("--ny", type=int, default=41)
    b.add_argument("--fmax", type=float, default=1500.0)
    b.add_argument("--reference", action="store_true")
    b.add_argument("--tune", action="store_true")
    b.add_argument("--no-modal", action="store_true",
                   help="leave out the [modal] pair (squeal then builds one from the "
                        "symmetric parts)")
    b.add_argument("--cases", default=None,
                   help="W:mu pairs of the reference, comma separated (default: "
                        + ",".join(f"{w:g}:{m:g}" for w, m in BRAKE_CASES) + ")")
    f = sub.add_parser("mat-fixtures")
    f.add_argument("out")
    args = p.parse_args()
    if args.cmd == "operator":
        which = CASES
        if args.cases:
            which = [tuple(float(x) for x in c.split(":")) for c in args.cases.split(",")]
        write_operator(args.out, args.nx, args.ny, args.reference, args.fmax, which)
    elif args.cmd == "brake":
        if args.tune:
            tune(args.nx, args.ny, args.fmax)
        which = BRAKE_CASES
        if args.cases:
            which = [tuple(float(x) for x in c.split(":")) for c in args.cases.split(",")]
        write_brake(args.out, args.nx, args.ny, args.reference, args.fmax, which,
                    modal=not args.no_modal)
    else:
        mat_fixtures(args.out)


if __name__ == "__main__":
    main()
