#!/usr/bin/env python3
"""The paper case in scipy's DOP853 at rtol 1e-10, timed beside clutchpack's reference engine
(issue 46's speed goal: the reference engine at least 500x faster; docs/performance.md).

The model is docs/MODEL.md sections 1-4 at h_o = 0 (scenes/hu-table2.toml): one friction disc
of J2 on a shaft whose speed is prescribed (eq 3), coupled by the dry tooth law (eqs 1, 2, 6),
written here independently of clutchpack as two first-order equations in the relative angle
phi = theta_shaft - theta_disc and the disc's speed:

    phi'  = omega_shaft(t) - omega_disc,   omega_shaft = omega_0 + A sin(2 pi f t)
    J2 omega_disc' = -n F Rb - C2 omega_disc
    delta = (|phi| - g0) Rb,  v_n = sign(phi) (omega_shaft - omega_disc) Rb
    |F| = max(0, (1 + p v_n) H delta^1.5) for delta > 0,  F = -sign(phi) |F|,  H = 4/3 E sqrt(r)

integrated by `scipy.integrate.solve_ivp(method="DOP853", rtol=1e-10)` over the paper's 0.3 s,
with the reference engine's own absolute tolerances scaled to that rtol (phi: rtol g0; the
speed: rtol rad/s; crates/reference/src/stepper.rs). The timed scipy run is the plainest one
(no events, no dense output: scipy's cheapest way through the run); a second, untimed run
with the contacts as events and dense output finds each impact's peak, and the first impacts
are checked against clutchpack's (`clutchpack run scenes/hu-table2.toml --impacts-csv`; the
rattle is chaotic, so only the first ~0.1 s agree impact for impact, MODEL.md section 6).

clutchpack's side is its in-process time per run of the same case (`clutchpack bench`'s
"paper case" line: the median of --runs runs); the ratio is scipy's median over clutchpack's
median, each side timed in turn in every round (the same minute).

    python3 bench/scipy/paper.py                  # 5 rounds
    python3 bench/scipy/paper.py --rounds 7 --clutchpack target/release/clutchpack

Everything it makes goes under target/scipy/ (or $CARGO_TARGET_DIR/scipy): a virtual
environment with the pinned scipy and numpy of bench/scipy/requirements.txt from PyPI, and the
impacts file. clutchpack is target/release/clutchpack (build it first: `cargo build
--release`) unless --clutchpack names another binary.
"""
import argparse
import csv
import hashlib
import math
import os
import re
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
WORK = os.path.join(TARGET, "scipy")
VENV = os.path.join(WORK, "venv")
REQUIREMENTS = os.path.join(HERE, "requirements.txt")
SCENE = os.path.join(ROOT, "scenes", "hu-table2.toml")

RTOL = 1e-10
DURATION_S = 0.3
# Table 2 and the parameters MODEL.md section 4 fixes (scenes/hu-table2.toml).
N_TEETH = 154
R_M = 0.231
ALPHA_RAD = math.radians(20.0)
BACKLASH_M = 0.75e-3
E_PA = 210e9
CURVATURE_M = 1.75e-3
LOSS_S_M = 0.8
J2_KG_M2 = 0.156
C2_N_M_S = 0.01
OMEGA0, AMPLITUDE, FREQUENCY = 200.0, 4.378, 104.0

RB_M = R_M * math.cos(ALPHA_RAD)
G0_RAD = BACKLASH_M / (2.0 * R_M)
H = 4.0 / 3.0 * E_PA * math.sqrt(CURVATURE_M)
W = 2.0 * math.pi * FREQUENCY


def ensure_venv():
    """Re-runs this script inside target/scipy/venv, made (scipy and numpy installed) first."""
    python = os.path.join(VENV, "bin", "python")
    if os.path.realpath(sys.prefix) == os.path.realpath(VENV):
        return
    stamp = os.path.join(VENV, ".requirements.sha256")
    want = hashlib.sha256(open(REQUIREMENTS, "rb").read()).hexdigest()
    if not (os.path.exists(python) and os.path.exists(stamp) and open(stamp).read() == want):
        print(f"paper.py: making {VENV} (pip install -r {REQUIREMENTS})", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "venv", "--clear", VENV], check=True)
        subprocess.run([python, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                        "-r", REQUIREMENTS], check=True)
        open(stamp, "w").write(want)
    os.execv(python, [python, os.path.abspath(__file__)] + sys.argv[1:])


def tooth_load_n(t, phi, omega_disc):
    """The per-tooth load F, N (MODEL.md sections 1, 2: the dry law; < 0 while the shaft
    leads)."""
    delta = (abs(phi) - G0_RAD) * RB_M
    if delta <= 0.0:
        return 0.0
    sign = 1.0 if phi > 0.0 else -1.0
    v_n = sign * (OMEGA0 + AMPLITUDE * math.sin(W * t) - omega_disc) * RB_M
    return -sign * max(0.0, (1.0 + LOSS_S_M * v_n) * H * delta**1.5)


def rhs(t, y):
    """(phi', omega_disc') of MODEL.md section 3 (eq 5) with the shaft prescribed (eq 3)."""
    phi, omega_disc = y
    f = tooth_load_n(t, phi, omega_disc)
    return [OMEGA0 + AMPLITUDE * math.sin(W * t) - omega_disc,
            (-N_TEETH * f * RB_M - C2_N_M_S * omega_disc) / J2_KG_M2]


def solve(**extra):
    """The paper's run in DOP853 at RTOL: phi(0) = 0 (centred), the disc at omega_0."""
    from scipy.integrate import solve_ivp
    return solve_ivp(rhs, (0.0, DURATION_S), [0.0, OMEGA0], method="DOP853", rtol=RTOL,
                     atol=[RTOL * G0_RAD, RTOL], **extra)


def impacts(n_max):
    """The first `n_max` impacts of an untimed run with the contacts' onsets and separations
    as events and dense output: each one's (peak time s, peak load N), the peak refined on
    the dense output."""
    from scipy.optimize import minimize_scalar

    def contact(t, y):
        return abs(y[0]) - G0_RAD
    sol = solve(events=contact, dense_output=True)
    edges = sorted(sol.t_events[0])
    out = []
    # a contact opens at an even edge and closes at the next (phi starts centred)
    for on, off in zip(edges[0::2], edges[1::2]):
        def load(t):
            y = sol.sol(t)
            return tooth_load_n(t, y[0], y[1])
        sign = 1.0 if load(0.5 * (on + off)) >= 0.0 else -1.0
        best = minimize_scalar(lambda t: -sign * load(t), bounds=(on, off), method="bounded",
                               options={"xatol": 1e-12})
        out.append((best.x, load(best.x)))
        if len(out) == n_max:
            break
    return out


def clutchpack_impacts(binary, n_max):
    """The first `n_max` impacts of `clutchpack run scenes/hu-table2.toml` (peak time s, peak
    load N)."""
    os.makedirs(WORK, exist_ok=True)
    path = os.path.join(WORK, "hu-table2-impacts.csv")
    subprocess.run([binary, "run", SCENE, "--impacts-csv", path, "--no-record"], check=True,
                   stdout=subprocess.DEVNULL)
    rows = list(csv.DictReader(open(path)))
    return [(float(r["t_peak_s"]), float(r["peak_n"])) for r in rows[:n_max]]


def clutchpack_ms_per_run(binary, runs):
    """clutchpack's in-process time per run of the paper case, ms (`bench`'s paper-case line:
    the median of `runs`)."""
    out = subprocess.run([binary, "bench", "--runs", str(runs), "--paper-only"], check=True,
                         capture_output=True, text=True).stdout
    m = re.search(r"paper case \(0\.3 s, 1 disc\): ([0-9.]+) ms per run", out)
    if not m:
        sys.exit(f"paper.py: no paper-case line in `{binary} bench`'s output:\n{out}")
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5, help="rounds, each side timed in turn")
    ap.add_argument("--scipy-runs", type=int, default=3,
                    help="scipy runs per round (the median is the round's)")
    ap.add_argument("--runs", type=int, default=20,
                    help="clutchpack runs per round (`bench --runs`, the median is the round's)")
    ap.add_argument("--clutchpack", default=os.path.join(TARGET, "release", "clutchpack"),
                    help="the clutchpack binary (a release build)")
    ap.add_argument("--compare", type=int, default=10,
                    help="impacts compared one by one with clutchpack's")
    a = ap.parse_args()
    if a.rounds < 1 or a.scipy_runs < 1 or a.runs < 1 or a.compare < 1:
        sys.exit("paper.py: --rounds, --scipy-runs, --runs and --compare must be >= 1")
    if not os.access(a.clutchpack, os.X_OK):
        sys.exit(f"paper.py: --clutchpack {a.clutchpack}: not an executable (build it: "
                 "cargo build --release)")
    ensure_venv()
    import numpy
    import scipy
    print(f"scipy {scipy.__version__}, numpy {numpy.__version__}, Python "
          f"{sys.version.split()[0]}; DOP853 rtol {RTOL:g}, atol [{RTOL * G0_RAD:.3g} rad, "
          f"{RTOL:g} rad/s]")

    # agreement: the first impacts, peak time and load
    ours, theirs = impacts(a.compare), clutchpack_impacts(a.clutchpack, a.compare)
    if len(ours) < a.compare or len(theirs) < a.compare:
        sys.exit(f"paper.py: {len(ours)} impacts in scipy's run, {len(theirs)} in clutchpack's; "
                 f"expected at least {a.compare}")
    worst_t = max(abs(x[0] - y[0]) for x, y in zip(ours, theirs))
    worst_f = max(abs(x[1] - y[1]) / abs(y[1]) for x, y in zip(ours, theirs))
    for k, (x, y) in enumerate(zip(ours, theirs)):
        print(f"  impact {k + 1}: scipy {x[1]:+9.3f} N at {x[0] * 1e3:.5f} ms, clutchpack "
              f"{y[1]:+9.3f} N at {y[0] * 1e3:.5f} ms")
    print(f"first {a.compare} impacts: peak times within {worst_t:.2e} s, peaks within "
          f"{worst_f:.2e} (relative)")
    if worst_f > 1e-3 or worst_t > 1e-6:
        sys.exit("paper.py: scipy's and clutchpack's first impacts disagree (over 1e-3 in a "
                 "peak or 1 us in its time): the models differ, a ratio would mean nothing")

    scipy_s, ours_ms, ratios = [], [], []
    for r in range(a.rounds):
        times = []
        for _ in range(a.scipy_runs):
            t0 = time.perf_counter()
            sol = solve()
            times.append(time.perf_counter() - t0)
            if sol.status != 0:
                sys.exit(f"paper.py: solve_ivp failed: {sol.message}")
        s = statistics.median(times)
        c = clutchpack_ms_per_run(a.clutchpack, a.runs)
        scipy_s.append(s)
        ours_ms.append(c)
        ratios.append(s / (c * 1e-3))
        print(f"round {r + 1}: scipy {s:.3f} s per run ({sol.t.size - 1} steps, {sol.nfev} "
              f"evaluations), clutchpack {c:.3f} ms per run: {ratios[-1]:.0f}x")
    print(f"median over {a.rounds} rounds: scipy {statistics.median(scipy_s):.3f} s, clutchpack "
          f"{statistics.median(ours_ms):.3f} ms, ratio {statistics.median(ratios):.0f}x "
          f"(rounds {min(ratios):.0f}-{max(ratios):.0f}x); goal 500x")


if __name__ == "__main__":
    main()
