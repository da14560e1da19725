"""Type stubs of the native module (crates/python/src/lib.rs). Units: SI."""

from os import PathLike
from typing import List, Optional, Sequence, Tuple, Union

_Path = Union[str, PathLike[str]]

__version__: str

class Scene:
    """A validated scene."""
    @property
    def name(self) -> str: ...
    @property
    def text(self) -> str: ...
    @property
    def overrides(self) -> List[str]: ...
    @property
    def duration_s(self) -> float:
        """Simulated duration, s."""
    @property
    def bodies(self) -> List[str]:
        """Friction discs, then separator plates."""
    @property
    def is_network(self) -> bool:
        """Whether the scene is a driveline network ([[bodies]])."""
    @property
    def path(self) -> Optional[str]: ...
    def engine_line(self, engine: Optional[str] = None) -> str: ...
    def with_sets(self, sets: Sequence[Tuple[str, str]]) -> "Scene": ...

class ImpactColumns:
    """One entry per impact: body, onset/peak/separation times (s), flank, closing speed at
    onset (m/s), signed peak per-tooth load (N)."""
    disc: List[str]
    t_on_s: List[float]
    t_peak_s: List[float]
    t_off_s: List[float]
    flank: List[str]
    v_on_m_s: List[float]
    peak_n: List[float]

class RawRun:
    """A run of a pack or a network scene: its summary (JSON text), engine line, a pack's
    impacts, the sample times (s) and the columns at them (a pack's per-tooth load per body,
    N; a network's ``<body>.speed_rad_s``, rad/s, and ``<coupling>.torque_n_m``, N m)."""

    summary_json: str
    engine_line: str
    impacts: ImpactColumns
    sample_t_s: List[float]
    sample_columns: List[Tuple[str, List[float]]]
    recording: Optional[str]
    stopped_early: bool
    warnings: List[str]

class RawRecording:
    summary_json: str
    scene_text: Optional[str]
    overrides: List[str]
    impacts: ImpactColumns
    loads: List[Tuple[str, List[float], List[float]]]
    warning: Optional[str]
    sample_t_s: List[float]
    sample_columns: List[Tuple[str, List[float]]]

def load_scene(
    path: Optional[_Path] = None,
    text: Optional[str] = None,
    name: Optional[str] = None,
    sets: Sequence[Tuple[str, str]] = ...,
) -> Scene: ...
def scene_from_json(json: str, name: str, sets: Sequence[Tuple[str, str]] = ...) -> Scene: ...
def run(
    scene: Scene,
    engine: Optional[str] = None,
    record: Optional[_Path] = None,
    impacts_csv: Optional[_Path] = None,
    keep_samples: bool = True,
    deterministic: bool = False,
) -> RawRun: ...
def sweep(
    scene: Scene,
    param: str,
    values: Sequence[float],
    ensemble: int = 1,
    jobs: Optional[int] = None,
    engine: Optional[str] = None,
) -> str: ...
def read(path: _Path, salvage: bool = False) -> RawRecording: ...

class RawFit:
    """A fit's summary (JSON text), its series per signal (name, rows, measured, fitted)
    and the fitted scene's TOML text."""

    summary_json: str
    series: List[Tuple[str, List[float], List[float], List[float]]]
    fitted_scene: str

def fit(
    scene: _Path,
    data: _Path,
    params: List[str],
    matches: List[str],
    sets: List[Tuple[str, str]] = [],
    engine: Optional[str] = None,
    time_column: str = "time_s",
    variant: Optional[str] = None,
    ensemble: int = 1,
    max_iterations: int = 100,
    fd_step: float = 1e-6,
    fitted_scene: Optional[_Path] = None,
) -> RawFit: ...
def study_run(
    study: _Path, out: _Path, jobs: Optional[int] = None, shard: int = 0, shards: int = 1
) -> Tuple[str, int, int, int, int, bool]: ...
def study_merge(dir: _Path, plot_format: str = "png") -> str: ...

class StepperState:
    """A saved state of a Stepper."""

class Stepper:
    """A pack or a network scene's run advanced call by call (``clutchpack.Simulation`` wraps
    it); ``drive``: a pack's inputs by their FMU names (``"piston.pressure_pa"``, ...) or
    their older aliases (``"piston_pressure"``), a network's
    (``"bodies.<body>.speed_rad_s"`` of a prescribed body, ``"bodies.<body>.drive_torque_n_m"``,
    ``"couplings.<clutch>.normal_force_n"``,
    ``"couplings.<pack>.pressure_pa"``)."""
    def __init__(
        self,
        scene: Scene,
        engine: Optional[str] = None,
        drive: Sequence[str] = ...,
        record: Optional[str] = None,
        stop_time: Optional[float] = None,
    ) -> None: ...
    @property
    def time(self) -> float:
        """The run's time, s."""
    def variables(self) -> List[Tuple[str, str, str, str]]:
        """(name, causality, unit, description) of every variable."""
    def set_input(
        self, name: str, value: float, slope: Optional[float] = None, curvature: Optional[float] = None
    ) -> None: ...
    def advance_to(self, t: float) -> None: ...
    def outputs(self) -> List[Tuple[str, float]]: ...
    def save(self) -> StepperState: ...
    def restore(self, state: StepperState) -> None: ...
    def finish(self) -> str:
        """The run's summary, a pack's or a network's (JSON text)."""
