#!/usr/bin/env python3
"""Solve squeal's frictional QEP band with SLEPc and compare with squeal's own solve.

Reads an operator directory written by `squeal export` (Mc.mtx, Kc.mtx, FM.mtx, FK.mtx),
forms M~ = Mc - mu FM and K~ = Kc - mu FK (C = 0) and finds every mode of the band as a
generalized non-Hermitian eigenproblem in s = -lambda^2, the linearization a SLEPc user
picks when there is no damping:

    (K~ - s M~) u = 0,   EPS type krylovschur, problem type GNHEP,
    ST sinvert with target sigma (EPS_TARGET_MAGNITUDE),
    KSP preonly + PC lu with MUMPS (`--ordering` picks MUMPS's ICNTL(7)),
    tolerance `--tol` on SLEPc's relative error estimate (EPS_CONV_REL).

The band is squeal's (`band_hz` of its `stability --json`), unless `--band` says otherwise.
Windows, nev doubling and the split rule are those of squeal's band driver and of
`scipy_compare.py`: a window [lo, hi] Hz has sigma = ((2 pi lo)^2 + (2 pi hi)^2) / 2 and
radius R = 1.05 (b - a) / 2 + 0.01 (2 pi hi)^2; nev starts at 24 and doubles until one
converged eigenvalue lies outside |s - sigma| > R. The EPS object (and with it the MUMPS
factor of K~ - sigma M~) is kept while nev grows: one factorization per window.
Backward errors, the matching of modes and the side-by-side table are `scipy_compare.py`'s.

Under `mpiexec -n N` the matrices are distributed by rows over the N processes (PETSc's
default layout), MUMPS factorizes and solves on all of them, and the first process gathers
the eigenvectors, computes the backward errors and writes the report.

Writes slepc.json and, given squeal's `stability --json` output, prints the comparison.
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scipy_compare import (TWO_PI, band_modes, keep_new, load_operator,  # noqa: E402
                           parse_args, write_and_compare)

import petsc4py  # noqa: E402

# the event log counts MUMPS factorizations (MatLUFactorNum); its report goes nowhere
petsc4py.init(sys.argv[:1] + ["-log_view", ":/dev/null"])
from petsc4py import PETSc  # noqa: E402
import slepc4py  # noqa: E402

slepc4py.init(sys.argv[:1])
from slepc4py import SLEPc  # noqa: E402

# MUMPS orderings: sequential analysis (ICNTL(28) = 1) with ICNTL(7), or parallel analysis
# (ICNTL(28) = 2) with ICNTL(29); MUMPS falls back to another ordering when the one asked
# for is not in its build, so the one used (INFOG(7)) is reported.
ORDERINGS = {"auto": (1, 7), "amd": (1, 0), "amf": (1, 2), "scotch": (1, 3), "pord": (1, 4),
             "metis": (1, 5), "qamd": (1, 6), "ptscotch": (2, 1), "parmetis": (2, 2)}
USED = {0: "amd", 1: "given", 2: "amf", 3: "scotch", 4: "pord", 5: "metis", 6: "qamd"}


COMM = PETSc.COMM_WORLD
ROOT = COMM.getRank() == 0


def say(msg):
    """Prints `msg` to standard error from the first process only."""
    if ROOT:
        print(msg, file=sys.stderr)


def petsc_matrix(a):
    """`a` as a PETSc AIJ matrix on every process, each holding its block of rows (PETSc's
    default split: the first `n % size` processes one row more)."""
    a = a.tocsr()
    a.sort_indices()
    n, size, rank = a.shape[0], COMM.getSize(), COMM.getRank()
    local = n // size + (1 if rank < n % size else 0)
    start = rank * (n // size) + min(rank, n % size)
    rows = a[start:start + local]
    return PETSc.Mat().createAIJ(size=((local, n), (local, n)),
                                 csr=(rows.indptr, rows.indices, rows.data), comm=COMM)


class SlepcBand:
    """squeal's band driver on SLEPc's Krylov-Schur with MUMPS shift-and-invert."""

    def __init__(self, m, k, tol, ordering, max_nev=400, nev0=24, radius_factor=1.05,
                 margin_rel=0.01, max_depth=10):
        self.m, self.k = m, k
        self.pm, self.pk = petsc_matrix(m), petsc_matrix(k)
        self.n = m.shape[0]
        self.tol, self.ordering = tol, ordering
        self.cap = max(1, min(max_nev, self.n - 2))
        self.nev0, self.max_depth = nev0, max_depth
        self.radius_factor, self.margin_rel = radius_factor, margin_rel
        self.lam, self.vecs = [], []
        self.windows = self.factorizations = 0
        self.ordering_used = None
        self.factor_entries = None
        self.setup_s = 0.0
        self.notes = []

    def eps(self, sigma):
        opts = PETSc.Options()
        analysis, order = ORDERINGS[self.ordering]
        # the options of the factor matrix carry the ST's prefix
        opts["st_mat_mumps_icntl_28"] = analysis
        opts["st_mat_mumps_icntl_7" if analysis == 1 else "st_mat_mumps_icntl_29"] = order
        e = SLEPc.EPS().create()
        e.setOperators(self.pk, self.pm)
        e.setProblemType(SLEPc.EPS.ProblemType.GNHEP)
        e.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
        e.setTarget(sigma)
        e.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
        e.setTolerances(self.tol, 100000)
        e.setConvergenceTest(SLEPc.EPS.Conv.REL)
        st = e.getST()
        st.setType(SLEPc.ST.Type.SINVERT)
        st.setShift(sigma)
        ksp = st.getKSP()
        ksp.setType(PETSc.KSP.Type.PREONLY)
        pc = ksp.getPC()
        pc.setType(PETSc.PC.Type.LU)
        pc.setFactorSolverType("mumps")
        e.setFromOptions()
        return e

    def window(self, lo, hi, depth, nev0):
        a, b = (TWO_PI * lo) ** 2, (TWO_PI * hi) ** 2
        sigma = 0.5 * (a + b)
        radius = self.radius_factor * 0.5 * (b - a) + self.margin_rel * (TWO_PI * hi) ** 2
        e = self.eps(sigma)
        nev = min(max(nev0, 1), self.cap)
        e.setDimensions(nev=nev)
        t0 = time.perf_counter()
        e.setUp()  # the MUMPS factorization of K~ - sigma M~
        self.setup_s += time.perf_counter() - t0
        factor = e.getST().getKSP().getPC().getFactorMatrix()
        self.ordering_used = USED.get(factor.getMumpsInfog(7), str(factor.getMumpsInfog(7)))
        # INFOG(29): entries in the factors (negative: in millions)
        entries = factor.getMumpsInfog(29)
        self.factor_entries = entries if entries >= 0 else -entries * 1_000_000
        self.factorizations += 1
        while True:
            e.setDimensions(nev=nev)
            e.solve()
            nconv = e.getConverged()
            s = np.array([e.getEigenvalue(i) for i in range(nconv)], dtype=complex)
            reach = np.max(np.abs(s - sigma)) if nconv else 0.0
            if nconv < nev:
                self.notes.append(f"window [{lo:.6g}, {hi:.6g}] Hz: {nconv}/{nev} converged")
                break
            if reach > radius:
                break
            if nev >= self.cap:
                if depth < self.max_depth:
                    mid = 0.5 * (lo + hi)
                    nxt = min(max(nev // 2, self.nev0), self.cap)
                    self.notes.append(f"window [{lo:.6g}, {hi:.6g}] Hz split")
                    e.destroy()
                    self.window(lo, mid, depth + 1, nxt)
                    self.window(mid, hi, depth + 1, nxt)
                    return
                self.notes.append(f"window [{lo:.6g}, {hi:.6g}] Hz not covered")
                break
            nev = min(2 * nev, self.cap)
        self.windows += 1
        its = e.getIterationNumber()
        say(f"  slepc window [{lo:.0f}, {hi:.0f}] Hz: nev = {nev}, {nconv} converged, "
            f"{its} restarts")
        vr, vi = self.pk.createVecs()
        gather, whole = PETSc.Scatter.toZero(vr)

        def on_root(v):
            # the whole vector on the first process (a collective call: every process
            # makes it, in the same order, as keep_new's choices depend on values only)
            gather.scatter(v, whole, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
            return whole.getArray().copy() if ROOT else None

        def pairs():
            for j in range(nconv):
                sj = e.getEigenpair(j, vr, vi)
                # principal root: Im(lambda) >= 0; the vector is read before the next pair
                re, im = on_root(vr), on_root(vi)
                vector = re + 1j * im if ROOT else None
                yield 1j * np.sqrt(complex(sj)), lambda v=vector: v

        keep_new(self, lo, hi, pairs())
        e.destroy()


def solve_band(m, k, fmin, fmax, tol, ordering):
    band = SlepcBand(m, k, tol, ordering)
    t0 = time.perf_counter()
    band.window(fmin, fmax, 0, band.nev0)
    solve_s = time.perf_counter() - t0
    if not ROOT:
        return None, None, solve_s, band
    lam, eta = band_modes(band, m, k, fmin, fmax)
    return lam, eta, solve_s, band


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ordering", choices=sorted(ORDERINGS), default="auto",
                    help="MUMPS fill-reducing ordering (see ORDERINGS); default auto")
    args, sq, fmin, fmax = parse_args(ap, "slepc.json")

    t0 = time.perf_counter()
    m, k = load_operator(args.operator, args.mu)
    load_s = time.perf_counter() - t0
    version = ".".join(str(v) for v in SLEPc.Sys.getVersion())
    petsc_version = ".".join(str(v) for v in PETSc.Sys.getVersion())
    procs = COMM.getSize()
    say(f"SLEPc {version}, PETSc {petsc_version}: operator n = {m.shape[0]}, "
        f"nnz(M~) = {m.nnz}, nnz(K~) = {k.nnz}, read in {load_s:.2f}s, {procs} MPI "
        f"process(es)")
    lam, eta, solve_s, band = solve_band(m, k, fmin, fmax, args.tol, args.ordering)
    lu = PETSc.Log.Event("MatLUFactorNum").getPerfInfo()
    band.factorizations = int(lu["count"])
    if not ROOT:
        return
    settings = (f"EPS krylovschur GNHEP in s = -lambda^2, ST sinvert, KSP preonly, "
                f"PC lu MUMPS ordering {args.ordering} (used: {band.ordering_used}), "
                f"tol {args.tol:g} (EPS_CONV_REL), squeal's windows and nev doubling, "
                f"{procs} MPI process(es)")
    report = {
        "solver": f"SLEPc {version} / PETSc {petsc_version}", "settings": settings,
        "setup_s": band.setup_s, "factor_numeric_s": lu["time"], "mpi_processes": procs,
        "factor_entries": band.factor_entries,
    }
    extra = [("  of which factorization (s)", "", f"{band.setup_s:.2f}"),
             ("entries in the factors", "", f"{band.factor_entries:,}")]
    write_and_compare("SLEPc", "SLEPc", args, (fmin, fmax), m.shape[0], lam, eta, solve_s,
                      load_s, band, report, sq, extra, args.out or (args.operator / "slepc.json"))

if __name__ == "__main__":
    main()
