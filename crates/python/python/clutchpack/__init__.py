"""clutchpack: wet multi-disc clutch and brake pack simulator.

How hard the spline teeth of each friction disc and separator plate hit their carrier when
the shaft's speed fluctuates, how the oil film softens the impacts, which body suffers most,
and whether the pack survives. The same library the ``clutchpack`` command line calls: a run
from Python is a run of the CLI, number for number.

Units are SI everywhere (degrees only under keys ending ``_deg``). Per-tooth loads are in N,
negative when the shaft (or carrier) leads, positive when the disc leads.

    >>> import clutchpack
    >>> r = clutchpack.run("scenes/hu-table2.toml")
    >>> r.summary["discs"][0]["max_positive_n"]      # N
    >>> r.impacts.head()                               # a pandas DataFrame

Bad input raises ``ValueError`` naming the key and the rule, as ``clutchpack check`` prints
it. An engine runs with the GIL released; Ctrl-C stops it within a fraction of a second,
its outputs (the recording) complete, and raises ``KeyboardInterrupt``.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import _clutchpack, study
from ._args import _integer, _number, _time
from ._clutchpack import Scene

__version__: str = _clutchpack.__version__

__all__ = [
    "Scene", "Result", "Sweep", "Simulation", "FitResult", "load_scene", "run", "sweep", "fit",
    "read", "study", "IMPACT_COLUMNS",
]

#: The columns of ``Result.impacts``, as in ``clutchpack run --impacts-csv``: body name,
#: onset, peak and separation times (s), flank (``drive`` or ``coast``... as the CSV), the
#: closing speed at onset (m/s) and the signed peak per-tooth load (N).
IMPACT_COLUMNS = ["disc", "t_on_s", "t_peak_s", "t_off_s", "flank", "v_on_m_s", "peak_n"]

PathLike = Union[str, "os.PathLike[str]"]
SceneLike = Union[Scene, PathLike, Mapping[str, Any], None]


def _sets(set: Optional[Mapping[str, Any]]) -> List[tuple]:
    """``{"defaults.oil.film_thickness_m": 25e-6}`` -> ``[("defaults...", "2.5e-05")]``,
    values written as the command line's ``--set KEY=VALUE`` takes them."""
    if set is not None and not isinstance(set, Mapping):
        raise TypeError(
            f"set = {set!r:.80}: expected a mapping of scene keys to values, e.g. "
            '{"defaults.oil.film_thickness_m": 25e-6}'
        )
    out = []
    for k, v in (set or {}).items():
        if isinstance(v, bool):
            text = "true" if v else "false"
        elif isinstance(v, (list, tuple, dict)):
            text = json.dumps(v)
        elif isinstance(v, (float, np.floating)):
            # float() first: numpy 2's repr of a numpy float is "np.float64(0.35)"
            text = repr(float(v))
        elif isinstance(v, np.integer):
            text = str(int(v))
        else:
            text = str(v)
        out.append((str(k), text))
    return out


def load_scene(
    scene: SceneLike = None, set: Optional[Mapping[str, Any]] = None, name: Optional[str] = None
) -> Scene:
    """A validated scene: a file path, a dict of the TOML file's tables, or ``None`` for the
    paper's case (built in); ``set`` overrides keys (dotted paths as in the file, e.g.
    ``{"discs[1].inertia_kg_m2": 0.2}``). Every problem raises ``ValueError`` at once, with
    its key, as ``clutchpack check`` prints it."""
    sets = _sets(set)
    if isinstance(scene, Scene):
        return scene.with_sets(sets) if sets else scene
    if scene is None:
        return _clutchpack.load_scene(sets=sets)
    if isinstance(scene, Mapping):
        return _clutchpack.scene_from_json(json.dumps(scene), name or "<dict>", sets)
    return _clutchpack.load_scene(path=os.fspath(scene), sets=sets)


def _impacts(raw: Any) -> pd.DataFrame:
    cols = raw.impacts
    data: Dict[str, Any] = {}
    for c in IMPACT_COLUMNS:
        v = getattr(cols, c)
        data[c] = v if c in ("disc", "flank") else np.asarray(v, dtype=float)
    return pd.DataFrame(data, columns=IMPACT_COLUMNS)


@dataclass
class Result:
    """A run (``run``) or a recording read back (``read``).

    - ``summary``: dict, what ``clutchpack run --summary-json`` writes (scene, engine,
      ``duration_s`` in s, ``steps``, per-body ``discs`` statistics in N, ``interfaces``,
      ``fatigue``); for a recording, its stored summary.
    - ``impacts``: DataFrame with ``IMPACT_COLUMNS``, one row per impact in time of closing.
    - ``samples``: DataFrame of the per-tooth load history (N) at the record rate, column
      ``t_s`` (s) and one column per body (a run); for a recording, per body, its load series
      (``loads``).
    - ``interfaces``: list of dicts, the stack's friction interfaces (clamp N, torque N m,
      lock time s, heat J); empty without a stack.
    - ``fatigue``: DataFrame, one row per body: damage rate (1/h), life (h), damage-equivalent
      load range (N).
    - ``recording``: the recording's path, if recorded; ``scene_text``: the scene as run.
    """

    summary: Dict[str, Any]
    impacts: pd.DataFrame
    samples: pd.DataFrame
    recording: Optional[str] = None
    engine_line: str = ""
    scene_text: Optional[str] = None
    overrides: List[str] = field(default_factory=list)
    loads: Dict[str, pd.DataFrame] = field(default_factory=dict)
    warnings: List[str] = field(default_factory=list)

    @property
    def interfaces(self) -> List[Dict[str, Any]]:
        return list(self.summary.get("interfaces", []))

    @property
    def fatigue(self) -> pd.DataFrame:
        rows = []
        for body, f in zip(self.summary.get("discs", []), self.summary.get("fatigue", [])):
            if not f:
                continue
            rows.append(
                {
                    "disc": body["name"],
                    "damage_rate_per_h": f["damage_rate_per_h"],
                    "life_h": np.nan if f["life_h"] is None else f["life_h"],
                    "eq_load_range_n": f["eq_load_range_n"],
                }
            )
        return pd.DataFrame(rows, columns=["disc", "damage_rate_per_h", "life_h", "eq_load_range_n"])

    def stats(self) -> pd.DataFrame:
        """The per-body statistics of ``summary["discs"]`` as a DataFrame (loads in N)."""
        return pd.DataFrame(self.summary.get("discs", []))


def run(
    scene: SceneLike = None,
    engine: Optional[str] = None,
    duration: Optional[float] = None,
    set: Optional[Mapping[str, Any]] = None,
    record: Optional[PathLike] = None,
    impacts_csv: Optional[PathLike] = None,
    keep_samples: bool = True,
    deterministic: bool = False,
) -> Result:
    """Runs a scene (a path, a dict, a ``Scene`` or ``None`` for the paper's case) as
    ``clutchpack run`` does. ``engine``: ``"reference"`` or ``"multibody"`` (default: the
    scene's choice); ``duration``: simulated time in s; ``set``: key overrides; ``record``:
    write the MCAP recording there; ``impacts_csv``: also write the impacts CSV.

    A driveline network (``[[bodies]]``) gives its summary (``couplings`` with each clutch's
    mode changes, lock times and heat; ``bodies``; ``energy``), ``samples`` with ``t_s``,
    ``<body>.speed_rad_s`` and ``<coupling>.torque_n_m`` columns, and every tooth impact (a
    gear mesh's, a resolved pack's disc's or plate's) in the CSV file ``impacts_csv`` if given
    (as ``--impacts-csv``: its first column ``name``, ``<pack>/discs/<disc>``; ``impacts`` is
    empty)."""
    s = dict(_sets(set))
    if duration is not None:
        s["simulation.duration_s"] = _time("duration", duration)
    sc = load_scene(scene, s)
    # one native run for either kind: a pack's samples are each body's per-tooth load (N), a
    # network's each body's speed and each coupling's torque
    raw = _clutchpack.run(
        sc,
        engine=engine,
        record=None if record is None else os.fspath(record),
        impacts_csv=None if impacts_csv is None else os.fspath(impacts_csv),
        keep_samples=keep_samples,
        deterministic=deterministic,
    )
    samples = pd.DataFrame({"t_s": np.asarray(raw.sample_t_s, dtype=float)})
    for name, values in raw.sample_columns:
        samples[name] = np.asarray(values, dtype=float)
    return Result(
        summary=json.loads(raw.summary_json),
        impacts=_impacts(raw),
        samples=samples,
        recording=None if raw.recording is None else os.fspath(raw.recording),
        engine_line=raw.engine_line,
        scene_text=sc.text,
        overrides=list(sc.overrides),
        warnings=list(raw.warnings),
    )


def read(path: PathLike, salvage: bool = False) -> Result:
    """A recording as a ``Result``: its summary, impacts and each body's load series
    (``loads[name]``: DataFrame ``t_s``, ``load_n``), and the scene it was run from; a network
    recording's summary is the run's and its ``samples`` are the run's (``t_s``,
    ``<body>.speed_rad_s``, ``<coupling>.torque_n_m``). A
    damaged file (cut by a kill) raises ``ValueError`` unless ``salvage``: then what could be
    read, with the damage in ``warnings``."""
    raw = _clutchpack.read(os.fspath(path), salvage=salvage)
    loads = {
        name: pd.DataFrame({"t_s": np.asarray(t, dtype=float), "load_n": np.asarray(v, dtype=float)})
        for name, t, v in raw.loads
    }
    # a network recording: its samples as `run` gives them (t_s, speeds, torques)
    samples = pd.DataFrame()
    if raw.sample_t_s:
        samples = pd.DataFrame({"t_s": np.asarray(raw.sample_t_s, dtype=float)})
        for name, values in raw.sample_columns:
            samples[name] = np.asarray(values, dtype=float)
    return Result(
        summary=json.loads(raw.summary_json),
        impacts=_impacts(raw),
        samples=samples,
        recording=os.fspath(path),
        scene_text=raw.scene_text,
        overrides=list(raw.overrides),
        loads=loads,
        warnings=[] if raw.warning is None else [raw.warning],
    )


@dataclass
class Sweep:
    """A sweep: ``rows`` (DataFrame: ``value``, ``disc``, and for each statistic its ensemble
    ``mean``, ``std``, ``min``, ``max``; loads in N) and ``summary`` (what
    ``clutchpack sweep --summary-json`` writes, but the fits)."""

    summary: Dict[str, Any]
    rows: pd.DataFrame


def sweep(
    scene: SceneLike,
    param: str,
    values: Sequence[float],
    ensemble: int = 1,
    jobs: Optional[int] = None,
    engine: Optional[str] = None,
    set: Optional[Mapping[str, Any]] = None,
) -> Sweep:
    """Runs ``scene`` once per value of the key ``param`` (as ``clutchpack sweep``), each value
    as an ensemble of ``ensemble`` members spread across the free play, on ``jobs`` threads."""
    ensemble = _integer("ensemble", ensemble, 1, _clutchpack.MAX_BATCH_CASES)
    jobs = None if jobs is None else _integer("jobs", jobs, 1)
    sc = load_scene(scene, set)
    text = _clutchpack.sweep(
        sc, param, [float(v) for v in values], ensemble=ensemble, jobs=jobs, engine=engine
    )
    summary = json.loads(text)
    flat = []
    for r in summary["rows"]:
        row = {"value": r["value"], "disc": r["disc"]}
        for stat in ("max_positive", "max_negative", "p99_abs", "impacts"):
            for k, v in r[stat].items():
                row[f"{stat}_{k}"] = v
        flat.append(row)
    return Sweep(summary=summary, rows=pd.DataFrame(flat))


@dataclass
class FitResult:
    """A fit (``fit``), as ``clutchpack fit`` reports it.

    - ``params``: DataFrame indexed by the key as asked: ``value``, ``std_error``,
      ``ci95_low``, ``ci95_high`` (the 95 % interval), ``start``, ``lower``, ``upper``,
      ``unit``, ``at_bound``, ``log`` (values in the key's unit).
    - ``residuals``: DataFrame, one row per measured point: ``signal``, ``x`` (the time in s,
      or the variant key's value), ``measured``, ``fitted`` and ``residual`` (fitted minus
      measured, unweighted; the signal's unit).
    - ``correlation``: DataFrame of the parameters' correlations (|r| > 0.99: not separately
      identifiable).
    - ``summary``: dict, what ``clutchpack fit --summary-json`` writes; ``warnings``: its
      warnings; ``fitted_scene``: the fitted scene's TOML text.
    """

    params: pd.DataFrame
    residuals: pd.DataFrame
    correlation: pd.DataFrame
    summary: Dict[str, Any]
    warnings: List[str]
    fitted_scene: str


def _strings(name: str, value: Union[str, Sequence[str]]) -> List[str]:
    if isinstance(value, str):
        return [value]
    if not isinstance(value, Sequence) or not all(isinstance(v, str) for v in value):
        raise TypeError(f"{name} = {value!r:.80}: expected a string or a list of strings")
    return list(value)


def fit(
    scene: PathLike,
    data: PathLike,
    params: Union[str, Sequence[str]],
    match: Union[str, Sequence[str]],
    set: Optional[Mapping[str, Any]] = None,
    engine: Optional[str] = None,
    time_column: str = "time_s",
    variant: Optional[str] = None,
    ensemble: int = 1,
    max_iterations: int = 100,
    fd_step: float = 1e-6,
    fitted_scene: Optional[PathLike] = None,
) -> FitResult:
    """Fits scene keys to measured series, as ``clutchpack fit`` (docs/calibration.md), with
    the same arguments: ``params`` as ``--param`` (``"KEY[=START][:LO:HI][:log]"``),
    ``match`` as ``--match`` (``"SIGNAL[=COLUMN][:WEIGHT]"``), ``set`` as ``--set`` (held
    fixed), ``variant``/``ensemble`` as ``--variant``/``--ensemble``; ``fitted_scene``:
    also write the fitted scene there. Bad input raises ``ValueError`` with the command
    line's message, before any run; Ctrl-C raises ``KeyboardInterrupt``."""
    if isinstance(scene, Scene):
        raise TypeError("scene: a fit needs the scene's file (a path), not a loaded Scene")
    ensemble = _integer("ensemble", ensemble, 1)
    max_iterations = _integer("max_iterations", max_iterations, 0)
    raw = _clutchpack.fit(
        os.fspath(scene),
        os.fspath(data),
        _strings("params", params),
        _strings("match", match),
        sets=_sets(set),
        engine=engine,
        time_column=time_column,
        variant=variant,
        ensemble=ensemble,
        max_iterations=max_iterations,
        fd_step=_number("fd_step", fd_step),
        fitted_scene=None if fitted_scene is None else os.fspath(fitted_scene),
    )
    summary = json.loads(raw.summary_json)
    keys = [p["key"] for p in summary["params"]]
    nan = float("nan")

    def num(x: Any) -> float:
        # an infinite interval end is null in the JSON
        return nan if x is None else float(x)

    params_df = pd.DataFrame(
        [
            {
                "key": p["key"],
                "value": p["value"],
                "std_error": num(p["std_error"]),
                "ci95_low": num(p["ci95_low"]),
                "ci95_high": num(p["ci95_high"]),
                "start": p["start"],
                "lower": num(p["lower"]),
                "upper": num(p["upper"]),
                "unit": p["unit"],
                "at_bound": p["at_bound"],
                "log": p["log"],
            }
            for p in summary["params"]
        ]
    ).set_index("key")
    frames = []
    for name, x, measured, fitted in raw.series:
        m = np.asarray(measured, dtype=float)
        f = np.asarray(fitted, dtype=float)
        frames.append(
            pd.DataFrame(
                {"signal": name, "x": np.asarray(x, dtype=float), "measured": m, "fitted": f,
                 "residual": f - m}
            )
        )
    residuals = pd.concat(frames, ignore_index=True)
    corr = pd.DataFrame(
        [[num(c) for c in row] for row in summary["correlation"]], index=keys, columns=keys
    )
    return FitResult(
        params=params_df,
        residuals=residuals,
        correlation=corr,
        summary=summary,
        warnings=list(summary["warnings"]),
        fitted_scene=raw.fitted_scene,
    )


class Simulation:
    """A run advanced call by call, for controllers and co-simulation written in Python: the
    FMU of ``clutchpack fmu`` as a Python object, with the same inputs, outputs and names.

        >>> sim = clutchpack.Simulation("scenes/pack-6-engagement.toml", drive=["piston.pressure_pa"])
        >>> for k in range(1, 301):
        ...     sim.advance_to(k * 1e-3, **{"piston.pressure_pa": controller(sim.outputs)})
        >>> summary = sim.finish()

    ``drive`` names the inputs the caller sets, by the FMU's names (``"shaft.speed_rad_s"``,
    ``"shaft.drive_torque_n_m"``, ``"drum.load_torque_n_m"``, ``"piston.pressure_pa"``; the
    older ``"shaft_speed"``, ``"shaft_torque"``, ``"drum_load"``, ``"piston_pressure"`` are
    kept as aliases); the others follow the scene's profiles (unlike an FMU, which drives every
    input its pack has: an input its host leaves unconnected holds its start value). A driven
    input holds its start value (the scene's at t = 0) until it is first set. Driving
    nothing, the run is the scene's run split into calls, impact for impact. An input set in
    ``advance_to`` is held from the current time until it is set again (docs/DECISIONS.md
    "Co-simulation"); ``slopes`` gives an input's slope (per s) for a first-order hold.
    Outputs (``outputs``, a dict): ``pack.shaft_torque_n_m`` (the pack's torque on the shaft,
    N m), per body ``discs[i].load_n`` (N), ``speed_rad_s``, ``torque_n_m``, ``max_load_n``,
    ``damage``, per interface ``interfaces[m].torque_n_m`` ..., ``impacts`` and the last
    impact (``last_impact.*``), as the FMU's (indices from 1). ``advance_to`` releases the GIL;
    Ctrl-C stops it (the run stands at an earlier time, everything before kept) and raises
    ``KeyboardInterrupt``.

    A network scene (``[[bodies]]``, on either engine) has the inputs
    ``bodies.<body>.drive_torque_n_m`` (N m), ``couplings.<clutch>.normal_force_n`` (N),
    ``couplings.<pack>.pressure_pa`` (Pa) and a prescribed body's ``bodies.<body>.speed_rad_s``
    (rad/s, as a pack's ``shaft.speed_rad_s``: its angle continuous, its speed the value),
    held from the instant they are set (no slopes), and the outputs
    ``bodies.<body>.speed_rad_s`` (a driven prescribed body's is its input, not an output)
    and ``.angle_rad``, ``couplings.<name>.torque_n_m`` and, for a clutch, ``.slip_rad_s``
    (w_b - w_a), ``.mode`` (Modelica's numbers: 2 free, 1 and -1 slipping, 0 locked) and
    ``.heat_j``; ``finish`` returns the network's summary:

        >>> sim = clutchpack.Simulation("scenes/dct-upshift-lumped.toml",
        ...     drive=["couplings.K1.normal_force_n", "couplings.K2.normal_force_n"])
        >>> for k in range(1, 1001):
        ...     sim.advance_to(k * 1e-3, **schedule(k * 1e-3))
    """

    def __init__(
        self,
        scene: SceneLike = None,
        engine: Optional[str] = None,
        drive: Iterable[str] = (),
        set: Optional[Mapping[str, Any]] = None,
        record: Optional[PathLike] = None,
        stop_time: Optional[float] = None,
    ) -> None:
        if stop_time is not None:
            stop_time = _time("stop_time", stop_time)
        if isinstance(drive, str):
            # a single name would be taken letter by letter
            drive = [drive]
        sc = load_scene(scene, set)
        self.scene: Scene = sc
        # one native stepper for a pack or a network scene (the sdk's co-simulation)
        self._s = _clutchpack.Stepper(
            sc, engine, list(drive), os.fspath(record) if record is not None else None, stop_time
        )
        #: Every variable: name -> (causality, unit, description).
        self.variables: Dict[str, tuple] = {
            name: (c, unit, doc) for name, c, unit, doc in self._s.variables()
        }
        #: The inputs the caller sets, by name (e.g. ``"shaft.speed_rad_s"``).
        self.inputs: List[str] = [n for n, v in self.variables.items() if v[0] == "input"]

    @property
    def time(self) -> float:
        """The time the run stands at, s."""
        return self._s.time

    @property
    def outputs(self) -> Dict[str, float]:
        """Every output now, by name (SI units; ``variables`` gives each unit)."""
        return dict(self._s.outputs())

    def advance_to(
        self, t: float, slopes: Optional[Mapping[str, float]] = None, **inputs: float
    ) -> "Simulation":
        """Sets ``inputs`` (by their names, e.g. ``**{"shaft.speed_rad_s": 201.0}``), held from
        now on, and advances to ``t`` (s). Unknown inputs raise ``ValueError`` naming the
        inputs this simulation has."""
        alone = [k for k in (slopes or {}) if k not in inputs]
        if alone:
            raise ValueError(f"slopes[{alone[0]!r}]: set the input's value with its slope")
        for name, value in inputs.items():
            slope = (slopes or {}).get(name)
            self._s.set_input(
                name,
                _number(name, value),
                None if slope is None else _number(f"slopes[{name!r}]", slope),
            )
        self._s.advance_to(float(t))
        return self

    def save(self) -> Any:
        """The whole state, to ``restore`` later (not while recording)."""
        return self._s.save()

    def restore(self, state: Any) -> None:
        """Back to a state from ``save``: advancing again gives the same outputs."""
        self._s.restore(state)

    def finish(self) -> Dict[str, Any]:
        """Ends the run (the recording finished) and returns its summary, as
        ``clutchpack run --summary-json`` (per-body statistics and fatigue)."""
        return json.loads(self._s.finish())
