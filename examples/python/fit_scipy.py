"""Calibration from Python, two ways (issue 47): Modelica's CoupledClutches
(scenes/coupled-clutches.toml), the clutches' friction coefficient mu and the step time of
clutch 2 fitted to a trace of the four inertias' speeds with 0.01 rad/s of noise,

1. with ``clutchpack.fit`` (the command line's ``clutchpack fit``: Levenberg-Marquardt, the
   intervals and correlations from its Jacobian), and
2. with ``scipy.optimize.least_squares`` driving runs of the scene through the wheel
   (``clutchpack.run`` with the keys ``set``), for users who prefer scipy's optimizers,

from the same start values (30 % off), and prints both. The trace is the wheel's own run at
the true values (mu = 0.5, 0.4 s) plus seeded noise, written to a temporary CSV file.

    pip install scipy   # scipy is not a dependency of clutchpack
    python examples/python/fit_scipy.py
"""

import os
import tempfile
import time

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

import clutchpack

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "scenes", "coupled-clutches.toml")
SD = 0.01  # rad/s: the trace's noise
TRUTH = {"mu": 0.5, "t2": 0.4}
START = [0.35, 0.52]
LOWER, UPPER = [0.05, 0.1], [2.0, 0.8]


def speeds(result: clutchpack.Result, t: np.ndarray) -> np.ndarray:
    """J1..J4's speeds of a network run at the times `t`, linear between the samples."""
    s = result.samples.drop_duplicates("t_s", keep="last")
    return np.concatenate(
        [np.interp(t, s["t_s"], s[f"J{j}.speed_rad_s"]) for j in range(1, 5)]
    )


def main() -> None:
    truth = clutchpack.run(SCENE).samples.drop_duplicates("t_s")
    t = truth["t_s"].to_numpy()
    rng = np.random.default_rng(47)
    trace = pd.DataFrame({"time_s": t})
    for j in range(1, 5):
        trace[f"w{j}"] = truth[f"J{j}.speed_rad_s"].to_numpy() + SD * rng.standard_normal(len(t))
    with tempfile.TemporaryDirectory() as d:
        data = os.path.join(d, "trace.csv")
        trace.to_csv(data, index=False, float_format="%.17g")

        started = time.perf_counter()
        f = clutchpack.fit(
            SCENE,
            data=data,
            params=[
                f"couplings[*].mu={START[0]}:{LOWER[0]}:{UPPER[0]}",
                f"couplings[1].force.start_s={START[1]}:{LOWER[1]}:{UPPER[1]}",
            ],
            match=[f"J{j}=w{j}:{1 / SD}" for j in range(1, 5)],
        )
        wall = time.perf_counter() - started
    print(f"clutchpack.fit: {f.summary['runs']} runs, {wall:.2f} s")
    print(f.params[["value", "std_error", "ci95_low", "ci95_high"]].to_string())
    print("correlation:\n" + f.correlation.round(4).to_string())

    measured = np.concatenate([trace[f"w{j}"].to_numpy() for j in range(1, 5)])
    runs = 0

    def residuals(x: np.ndarray) -> np.ndarray:
        nonlocal runs
        runs += 1
        mu, t2 = x
        r = clutchpack.run(
            SCENE,
            set={
                "couplings[0].mu": mu,
                "couplings[1].mu": mu,
                "couplings[2].mu": mu,
                "couplings[1].force.start_s": t2,
            },
        )
        return (speeds(r, t) - measured) / SD

    started = time.perf_counter()
    ls = least_squares(residuals, START, bounds=(LOWER, UPPER), x_scale="jac")
    wall = time.perf_counter() - started
    # the same linearised intervals from scipy's Jacobian: s^2 (J^T J)^-1, Student's t
    dof = len(ls.fun) - len(ls.x)
    s2 = 2 * ls.cost / dof
    cov = s2 * np.linalg.inv(ls.jac.T @ ls.jac)
    se = np.sqrt(np.diag(cov))
    from scipy.stats import t as student

    q = student.ppf(0.975, dof)
    print(f"scipy.optimize.least_squares: {runs} runs, {wall:.2f} s ({ls.message})")
    for name, x, e in zip(["couplings[*].mu", "couplings[1].force.start_s"], ls.x, se):
        print(f"{name:28s} {x:.8f}  se {e:.3e}  [{x - q * e:.8f}, {x + q * e:.8f}]")
    print(f"correlation: {cov[0, 1] / (se[0] * se[1]):+.4f}")
    print(f"true values: mu {TRUTH['mu']}, clutch 2's step time {TRUTH['t2']} s")


if __name__ == "__main__":
    main()
