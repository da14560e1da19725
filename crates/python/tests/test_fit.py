"""clutchpack.fit (issue 47) against the command line's `clutchpack fit`: the same numbers
from the same arguments, DataFrames of the parameters and the residuals, and bad input
raising ValueError with the command line's message.

Run by tests/python_package.rs (CLUTCHPACK_BIN: the CLI of the same checkout; the working
folder is the repository root), or alone:

    CLUTCHPACK_BIN=$PWD/target/debug/clutchpack target/pyenv-wheel/bin/python -m pytest \\
        -q -p no:cacheprovider crates/python/tests -k fit
"""

import json
import os
import subprocess

import numpy as np
import pandas as pd
import pytest

import clutchpack

BIN = os.environ["CLUTCHPACK_BIN"]
SCENE = "scenes/coupled-clutches.toml"
#: mu of every clutch and clutch 2's step time, 30 % from their true values (0.5, 0.4 s)
PARAMS = ["couplings[*].mu=0.35:0.05:2:log", "couplings[1].force.start_s=0.52:0.1:0.8"]
MATCH = [f"J{j}=w{j}" for j in range(1, 5)]


def trace(path, sd=0.0, seed=47):
    """J1..J4's speeds (rad/s) of the scene as shipped, every sample (1 ms), from the wheel's
    own run, with normal noise of standard deviation `sd` rad/s."""
    s = clutchpack.run(SCENE).samples.drop_duplicates("t_s")
    rng = np.random.default_rng(seed)
    df = pd.DataFrame({"time_s": s["t_s"].to_numpy()})
    for j in range(1, 5):
        df[f"w{j}"] = s[f"J{j}.speed_rad_s"].to_numpy() + sd * rng.standard_normal(len(s))
    df.to_csv(path, index=False, float_format="%.17g")


def cli_fit(tmp_path, data, params, match, check=True):
    out = tmp_path / "cli.json"
    args = [BIN, "fit", SCENE, "--data", str(data), "--summary-json", str(out),
            "--fitted-scene", str(tmp_path / "cli.fitted.toml")]
    for p in params:
        args += ["--param", p]
    for m in match:
        args += ["--match", m]
    p = subprocess.run(args, capture_output=True, text=True)
    if check:
        assert p.returncode == 0, p.stderr
        return json.loads(out.read_text())
    return p


def test_fit_recovers_coupled_clutches_as_the_cli_does(tmp_path):
    """From a noisy trace (0.01 rad/s, weight 100), `clutchpack.fit` returns the CLI's
    numbers exactly (one implementation; its runs are deterministic), the true values inside
    the 95 % intervals, mu within 1e-3 relative, a residual frame whose RMS per signal is the
    summary's, and the correlation matrix; `fitted_scene` writes the scene."""
    data = tmp_path / "trace.csv"
    trace(data, sd=0.01)
    match = [m + ":100" for m in MATCH]
    out = tmp_path / "py.fitted.toml"
    f = clutchpack.fit(SCENE, data=data, params=PARAMS, match=match, fitted_scene=out)
    assert list(f.params.columns[:4]) == ["value", "std_error", "ci95_low", "ci95_high"]
    assert list(f.params.index) == ["couplings[*].mu", "couplings[1].force.start_s"]
    for key, truth in [("couplings[*].mu", 0.5), ("couplings[1].force.start_s", 0.4)]:
        row = f.params.loc[key]
        assert row.ci95_low <= truth <= row.ci95_high, (key, row)
        assert abs(row.value - truth) < 1e-3 * truth, (key, row.value)
    cli = cli_fit(tmp_path, data, PARAMS, match)
    for p, c in zip(f.summary["params"], cli["params"]):
        for k in ("value", "std_error", "ci95_low", "ci95_high"):
            assert p[k] == c[k], (k, p, c)
    assert f.summary["runs"] == cli["runs"]
    assert set(f.residuals.columns) == {"signal", "x", "measured", "fitted", "residual"}
    assert len(f.residuals) == 4 * len(pd.read_csv(data))
    for s in f.summary["signals"]:
        r = f.residuals[f.residuals.signal == s["signal"]].residual.to_numpy()
        assert np.sqrt(np.mean(r**2)) == pytest.approx(s["rms"], rel=1e-9)
    assert f.correlation.shape == (2, 2)
    assert f.correlation.iloc[0, 0] == 1.0
    assert out.read_text() == f.fitted_scene
    assert "mu = " in f.fitted_scene


@pytest.mark.parametrize(
    "params,match,needle",
    [
        (["couplings[0].mux:0:1"], ["J1=w1"], "unknown key"),
        (["couplings[0].mu:1:0.1"], ["J1=w1"], "reversed"),
        (["couplings[0].peak:0.5:2"], ["J1=w1"], "outside the key's own rule"),
        (["couplings[0].mu:0:1"], ["J1=speed1"], 'no column "speed1"'),
        (["couplings[0].mu:0:1"], ["J9=w1"], "does not produce it"),
        (["couplings[0].mu:0"], ["J1=w1"], "bounds come as a pair"),
        (["couplings[0].mu:0:1"], ["J1=w1:-1"], "the weight must be > 0"),
    ],
)
def test_bad_fit_input_raises_the_cli_message(tmp_path, params, match, needle):
    """Bad input raises ValueError before any run, its message the one the CLI prints
    (exit 2)."""
    data = tmp_path / "d.csv"
    data.write_text("time_s,w1\n0,10\n0.001,10\n")
    with pytest.raises(ValueError) as e:
        clutchpack.fit(SCENE, data=data, params=params, match=match)
    msg = str(e.value)
    assert needle in msg, msg
    p = cli_fit(tmp_path, data, params, match, check=False)
    assert p.returncode == 2, p.stderr
    assert msg in p.stderr, (msg, p.stderr)


def test_numpy_numbers_as_set_values_are_numbers():
    """Regression (found by examples/python/fit_scipy.py, whose optimizer hands numpy floats
    to ``set``): a numpy float or integer is written as its number, not as numpy 2's repr
    ``np.float64(0.35)``, which the scene refused as not a number."""
    a = clutchpack.run(SCENE, set={"couplings[0].mu": np.float64(0.45)})
    b = clutchpack.run(SCENE, set={"couplings[0].mu": 0.45})
    assert a.summary["couplings"] == b.summary["couplings"]
    sc = clutchpack.load_scene(SCENE, set={"couplings[0].mu": np.float32(0.25),
                                           "simulation.record_rate_hz": np.int64(500)})
    assert "couplings[0].mu=0.25" in sc.overrides
    assert "simulation.record_rate_hz=500" in sc.overrides
