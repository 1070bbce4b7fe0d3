"""Rigid-body Euler equations: Lie-Poisson integrators and OpenMM's RATTLE against the exact solution.

    python examples/rigid_body_euler.py [out.png]        (default: rigid_body_paths.png)

Draws the body angular momentum x(t) of a rigid water molecule (an asymmetric top) on the sphere
|x| = |x0| for several methods against the exact curve (Jacobi elliptic functions), plus the error and
the drift of |x| over time, and prints the measured figures:

* the pure-numpy integrators of openmm_symprk.rigid.lie_poisson: measured orders and conservation;
* a rigid water run by openmm_symprk.SymplecticIntegrator (RATTLE) on OpenMM's Reference platform,
  with verlet and yoshida-4: error against the exact solution, measured order, drift of the space-frame
  angular momentum;
* the reduction itself: a rigid H2O2 (4 atoms) run by OpenMM's RATTLE equals the reduced RATTLE of
  Reich's Example 5.3 step by step.

Runs in about 10-20 s.
"""
from __future__ import annotations

import argparse
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from openmm_symprk.rigid import lie_poisson as rb  # noqa: E402
from openmm_symprk.rigid.free_body import (free_rigid_body, hydrogen_peroxide, rigid_water,  # noqa: E402
                                           run_free_rigid_body)

OMEGA = [6.0, -14.0, 9.0]  # body angular velocity at t = 0 (1/ps, principal axes, ascending moments)


def openmm_orders(body, T=0.5, steps=(100, 200, 400, 800)):
    lines = [f"OpenMM Reference, rigid water (moments {np.array2string(body.moments, precision=5)} Da nm²), "
             f"T = {T} ps, error = max_t |x - x_exact| / |x0|",
             f"{'method':10s} " + " ".join(f"{f'h={1000 * T / n:.3g} fs':>12s}" for n in steps) +
             f" {'order':>6s} {'max |ΔL|/|L|':>14s}"]
    for method in ("verlet", "yoshida-4"):
        errs, dL = [], 0.0
        for n in steps:
            t, x, L = run_free_rigid_body(body, method, T / n, n, record_every=n // 10)
            errs.append(np.abs(x - rb.exact_solution(body.x0, body.moments, t)).max() / np.linalg.norm(body.x0))
            dL = max(dL, np.abs(L - L[0]).max() / np.linalg.norm(L[0]))
        p = np.polyfit(np.log(T / np.array(steps)), np.log(errs), 1)[0]
        lines.append(f"{method:10s} " + " ".join(f"{e:12.3e}" for e in errs) + f" {p:6.2f} {dL:14.1e}")
    return "\n".join(lines)


def reduction_check(h=0.004, n=150):
    body = free_rigid_body(*hydrogen_peroxide(), OMEGA)
    t, x, _ = run_free_rigid_body(body, "verlet", h, n, record_every=1)
    red = rb.integrate(body.x0, body.moments, h, n, "rattle-1")
    ex = rb.exact_solution(body.x0, body.moments, t)
    s = np.linalg.norm(body.x0)
    return (f"Reduction (Theorem 5.1): rigid H2O2, OpenMM verlet/RATTLE vs lie_poisson 'rattle-1', h = {1000 * h:g} fs, "
            f"{n} steps:\n  max |x_OpenMM - x_rattle-1| / |x0| = {np.abs(x - red).max() / s:.1e}   "
            f"(both vs exact: {np.abs(x - ex).max() / s:.1e})")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", nargs="?", default="rigid_body_paths.png", help="PNG file to write")
    ap.add_argument("--quick", action="store_true", help="a short run and the chart only (a smoke test)")
    args = ap.parse_args(argv)
    t_start = time.time()

    body = free_rigid_body(*rigid_water(), OMEGA)
    M, x0 = body.moments, body.x0
    r0 = np.linalg.norm(x0)

    # A coarse step (h|ω| ~ 0.18) over ~40 turns, so that the methods' differences show on the chart.
    # (rattle-1 has no solution much beyond this step for water: planar, so it runs with shifted J.)
    h, n = (0.01, 250) if args.quick else (0.01, 2500)
    times = h * np.arange(n + 1)
    exact = rb.exact_solution(x0, M, times)
    runs = {}
    for name in ("splitting-1", "splitting-2", "rattle-1", "rk4"):
        runs[name] = rb.integrate(x0, M, h, n, name)
    _, x_v, _ = run_free_rigid_body(body, "verlet", h, n, record_every=1)
    _, x_y, _ = run_free_rigid_body(body, "yoshida-4", h, n, record_every=1)
    runs["OpenMM verlet"] = x_v
    runs["OpenMM yoshida-4"] = x_y

    fig = plt.figure(figsize=(15, 5.4))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    u, v = np.mgrid[0:2 * np.pi:40j, 0:np.pi:20j]
    ax.plot_wireframe(np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.85", linewidth=0.4)
    styles = {"splitting-1": "C3", "splitting-2": "C0", "rattle-1": "C2", "rk4": "C1",
              "OpenMM verlet": "C4", "OpenMM yoshida-4": "C9"}
    for name, path in runs.items():
        ax.plot(*(path[::3] / r0).T, ".", markersize=1.5, color=styles[name], label=name)
    fine = rb.exact_solution(x0, M, np.linspace(0, 0.6, 600)) / r0  # > one period of the exact orbit
    ax.plot(*fine.T, color="k", linewidth=1.2, label="exact")
    ax.set_title("x/|x0| on the sphere |x| = const", fontsize=10)
    ax.set_box_aspect((1, 1, 1))
    ax.legend(loc="upper left", fontsize=7, markerscale=6)

    ax2 = fig.add_subplot(1, 3, 2)
    for name, path in runs.items():
        ax2.semilogy(times[1:], np.linalg.norm(path - exact, axis=1)[1:] / r0, color=styles[name], label=name,
                     linewidth=0.8)
    ax2.set_xlabel("t (ps)")
    ax2.set_ylabel("|x - x_exact| / |x0|")
    ax2.set_title("error against the exact solution", fontsize=10)
    ax2.legend(fontsize=7)

    ax3 = fig.add_subplot(1, 3, 3)
    for name, path in runs.items():
        drift = np.abs(rb.casimir(path) / rb.casimir(x0) - 1)[1:]
        ax3.semilogy(times[1:], np.maximum(drift, 1e-17), color=styles[name], label=name, linewidth=0.8)
    ax3.set_xlabel("t (ps)")
    ax3.set_ylabel("| |x|² / |x0|² - 1 |")
    ax3.set_title("Casimir |x|²: round-off, except rk4", fontsize=10)
    ax3.legend(fontsize=7)
    fig.suptitle(f"Torque-free rigid water (asymmetric top): body angular momentum, h = {1000 * h:g} fs, "
                 f"{n} steps ({n * h:g} ps)", fontsize=11)
    fig.tight_layout()
    fig.savefig(args.out, dpi=130)

    if not args.quick:
        print(rb.report())
        print()
        print(openmm_orders(body))
        print()
        print(reduction_check())
    print(f"\nchart: {args.out}   ({time.time() - t_start:.1f} s)")


if __name__ == "__main__":
    main()
