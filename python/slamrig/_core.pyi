"""Type hints of slamrig's C++ core. Arrays marked "view" share the C++ buffer (read-only) and
keep its owner alive; the others are new arrays."""

from typing import Callable, Iterator, Optional, Protocol, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

class ConfigError(ValueError):
    """A bad scenario, option or flag; the message names file, line and key."""

class ParseError(ValueError):
    """A log or file that cannot be read; the message names file, line and field."""

class Pose2:
    """A rigid transform in SE(2), a_from_b; theta in (-pi, pi]."""
    def __init__(self, x: float = 0.0, y: float = 0.0, theta: float = 0.0) -> None: ...
    @property
    def x(self) -> float: ...
    @property
    def y(self) -> float: ...
    @property
    def theta(self) -> float: ...
    def inverse(self) -> Pose2: ...
    def between(self, other: Pose2) -> Pose2:
        """this^-1 * other: where `other` is, seen from this pose."""
    def __mul__(self, other: Pose2) -> Pose2: ...
    def __iter__(self) -> Iterator[float]: ...

PoseLike = Union[Pose2, Tuple[float, float, float], Sequence[float]]

class LaserScan:
    """One lidar sweep (REP-117): beam i at angle_min + i * angle_increment, time + i * time_increment."""
    def __init__(self, time_ns: int, angle_min: float, angle_increment: float,
                 ranges: npt.ArrayLike, range_min: float = 0.0, range_max: float = 30.0,
                 time_increment: float = 0.0, base_from_laser: Pose2 = ...) -> None: ...
    time_ns: int
    time: float
    angle_min: float
    angle_increment: float
    time_increment: float
    range_min: float
    range_max: float
    base_from_laser: Pose2
    @property
    def ranges(self) -> npt.NDArray[np.float32]:
        """Ranges in metres: a read-only view of the scan's buffer (no copy)."""
    @property
    def angles(self) -> npt.NDArray[np.float64]:
        """Beam angles in the laser frame (a new array)."""
    @property
    def hits(self) -> npt.NDArray[np.bool_]:
        """True where a beam is a return: range_min <= r < range_max."""

class OdometryPose:
    def __init__(self, time_ns: int, odom_from_base: Pose2) -> None: ...
    time_ns: int
    time: float
    odom_from_base: Pose2

class WheelTicks:
    def __init__(self, time_ns: int, right_ticks: Sequence[int], left_ticks: Sequence[int]) -> None: ...
    time_ns: int
    time: float
    right_ticks: npt.NDArray[np.int32]  # view
    left_ticks: npt.NDArray[np.int32]  # view

class ImuSample:
    def __init__(self, time_ns: int, angular_velocity: npt.ArrayLike,
                 linear_acceleration: npt.ArrayLike) -> None: ...
    time_ns: int
    time: float
    angular_velocity: npt.NDArray[np.float64]  # (3,) rad/s, view
    linear_acceleration: npt.NDArray[np.float64]  # (3,) m/s^2, gravity included, view

Record = Union[LaserScan, OdometryPose, WheelTicks, ImuSample]

class Trajectory:
    """Stamped poses, one per scan."""
    def __init__(self, rows: npt.ArrayLike) -> None:
        """From an (N, 4) array of t [s], x, y, yaw."""
    def __len__(self) -> int: ...
    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """(N, 3) x, y, yaw: a view (no copy)."""
    @property
    def stamps_ns(self) -> npt.NDArray[np.int64]:
        """(N,) nanosecond stamps: a view (no copy)."""
    @property
    def times(self) -> npt.NDArray[np.float64]:
        """Stamps in seconds (a new array)."""
    def interpolate(self, time_s: float) -> Optional[Pose2]: ...
    def path_length(self) -> float: ...

TrajectoryLike = Union[Trajectory, npt.ArrayLike]

class DiffDriveParams:
    wheel_radius_m: float
    ticks_per_revolution: int
    track_width_m: float
    def __init__(self) -> None: ...

class OccupancyGrid:
    """Log-odds grid; cell (ix, iy) covers origin + [ix, ix+1) * resolution; row 0 is the lowest y."""
    def __init__(self, resolution: float = 0.05) -> None: ...
    @staticmethod
    def from_log_odds(log_odds: npt.ArrayLike, origin: Tuple[float, float],
                      resolution: float) -> OccupancyGrid: ...
    resolution: float
    origin: Tuple[float, float]
    width: int
    height: int
    @property
    def log_odds(self) -> npt.NDArray[np.float32]:
        """(H, W) read-only copy of the cells at the time of the call."""
    def probability(self) -> npt.NDArray[np.float64]: ...
    def insert_scan(self, scan: LaserScan, world_from_base: Pose2,
                    max_range_m: Optional[float] = None) -> int:
        """max_range_m, when given, replaces the options' for this scan (a sparse scan's range)."""

class Dataset:
    """A log: records in time order (len, index, iterate; each record views the dataset) and
    the reference trajectory on its own channel."""
    def __len__(self) -> int: ...
    def __getitem__(self, i: int) -> Record: ...
    def __iter__(self) -> Iterator[Record]: ...
    def scans(self) -> list[LaserScan]: ...
    def scan_ranges(self) -> npt.NDArray[np.float32]:
        """(scans, beams) float32: one copy (each scan owns its own buffer)."""
    reference_stamps_ns: npt.NDArray[np.int64]  # view
    reference_poses: npt.NDArray[np.float64]  # (N, 3) view
    source: str
    format: str
    reference_kind: str
    notes: list[str]

def read_log(path: str, lenient: bool = False) -> Dataset:
    """Any log slamrig reads (CARMEN plain or .gz, ECE276A, ROS 2 bag); a relative path is also
    looked up in SLAMRIG_DATA_DIR. Raises ParseError naming file, line and field."""
def data_dir() -> str: ...

class TruthSample:
    time_ns: int
    time: float
    map_from_base: Pose2
    velocity: npt.NDArray[np.float64]
    yaw_rate: float
    true_ranges: npt.NDArray[np.float32]  # noise-free ranges of a scan, view

class StepResult:
    """What one physics step released; truth[i] belongs to records[i]."""
    time: float
    time_ns: int
    records: list[Record]
    truth: list[TruthSample]
    def __len__(self) -> int: ...

class Simulator:
    """The Box2D simulator on its own clock; same arguments and seed, same bits as `slamrig simulate`."""
    def __init__(self, world: str = "office", robot: str = "ece276a", seed: int = 1,
                 physics_rate_hz: float = 200.0, no_noise: bool = False, laps: int = 0) -> None: ...
    def step(self) -> StepResult: ...
    def run(self, until_s: float) -> list[StepResult]:
        """Steps until `until_s` without returning to Python; the steps that released records."""
    def flush(self) -> StepResult: ...
    def teleport(self, map_from_base: Pose2) -> None: ...
    def set_command(self, command: Optional[Tuple[float, float]]) -> None: ...
    def truth(self) -> TruthSample: ...
    time: float
    time_ns: int
    step_s: float
    drive_finished: bool

class ScanEstimate:
    def __init__(self, pose: Pose2, mean_pose: Optional[Pose2] = None,
                 trace: dict[str, float] = ..., covariance: Optional[npt.ArrayLike] = None) -> None: ...
    pose: Pose2
    mean_pose: Optional[Pose2]
    trace: dict[str, float]
    covariance: Optional[npt.NDArray[np.float64]]

class SyncedScan:
    """A scan with the odometry synchronised to its time (its own copy: arrays may be kept)."""
    scan: LaserScan
    odom_from_base: Pose2
    increment: Pose2
    dt: float
    distance: float
    yaw_change: float
    imu_samples: int

class OdometrySource:
    auto: OdometrySource
    wheel_ticks: OdometrySource
    poses: OdometrySource
    none: OdometrySource

class EstimatorConfig:
    def __init__(self, name: str, algorithm: str = "pf", **options: object) -> None:
        """Options as a scenario's `slam:` entry takes them; checked strictly (ConfigError)."""
    @staticmethod
    def python(name: str, estimator: object, **options: object) -> EstimatorConfig:
        """Runs `estimator` (a class, a factory or an instance); options go to the class."""
    name: str
    algorithm: str
    preset: str
    robot: DiffDriveParams
    def to_yaml(self) -> str: ...

class ScanSynchronizer:
    def __init__(self, config: EstimatorConfig, source: OdometrySource) -> None: ...
    def add(self, record: Record) -> list[SyncedScan]: ...
    def flush(self) -> list[SyncedScan]: ...

def resolve_odometry_source(dataset: Dataset, wanted: OdometrySource = ...) -> OdometrySource: ...
def algorithm_names() -> list[str]: ...

class Estimator:
    """Any algorithm of the table behind the C++ Estimator interface."""
    def __init__(self, config: EstimatorConfig, run_seed: int = 1) -> None: ...
    def add_record(self, record: Record) -> None: ...
    def record_estimate(self) -> Optional[ScanEstimate]: ...
    def add_scan(self, scan: SyncedScan) -> ScanEstimate: ...
    def finish(self) -> None: ...
    def revised_poses(self) -> Optional[list[Pose2]]: ...
    def map(self) -> OccupancyGrid:
        """A copy of the map now (the estimator keeps changing its own)."""
    def statistics(self) -> dict[str, float]: ...
    def loop_closures(self) -> list[Tuple[int, int, Pose2]]: ...
    def particles(self) -> npt.NDArray[np.float64]:
        """(N, 4) x, y, yaw, weight."""

class EstimatorRun:
    name: str
    algorithm: str
    online: Trajectory
    final: Trajectory
    mean: Trajectory
    record_rate: Trajectory
    map: OccupancyGrid
    statistics: dict[str, float]
    traces: dict[str, list[float]]
    trace_time_s: list[float]
    covariances: npt.NDArray[np.float64]
    wall_s: float

class EstimatorRunner:
    def __init__(self, config: EstimatorConfig, source: OdometrySource, run_seed: int = 1) -> None: ...
    def add(self, record: Record) -> None: ...
    def finish(self) -> None: ...
    def scans(self) -> int: ...
    def pose(self) -> Pose2: ...
    def take_result(self) -> EstimatorRun: ...

def run_estimator(config: EstimatorConfig, dataset: Dataset, run_seed: int = 1,
                  max_scans: int = 0) -> EstimatorRun:
    """Runs `config` over a whole log exactly as `slamrig slam` does."""

def ate(estimate: TrajectoryLike, reference: TrajectoryLike) -> dict:
    """ATE after SE(2) alignment: translation and rotation stats, reference_from_estimate."""
def rpe(estimate: TrajectoryLike, reference: TrajectoryLike, distance_m: float = 0.0) -> dict: ...
def score_map(estimate: OccupancyGrid, truth: OccupancyGrid, truth_from_estimate: Pose2 = ...,
              tolerance_cells: int = 1, occupied_probability: float = 0.65) -> dict: ...
def score_loop_closures(closures: Sequence[Tuple[int, int, Pose2]],
                        reference: TrajectoryLike) -> dict: ...
def nees(truth: npt.ArrayLike, estimate: npt.ArrayLike,
         covariances: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Pose NEES per row: (N, 3) truth and estimate, (N, 3, 3) covariances."""
def anees_bounds(dimension: int, runs: int) -> Tuple[float, float]: ...

class ScenarioSpec:
    path: str
    name: str
    description: str
    seed: int
    duration_s: float
    config_names: list[str]
    resolved_yaml: str
    def add_config(self, config: EstimatorConfig) -> None:
        """Runs `config` beside the file's configurations (e.g. EstimatorConfig.python(...))."""

def load_scenario(path: str, overrides: Sequence[str] = ..., seed: Optional[int] = None) -> ScenarioSpec:
    """A scenario file or shipped name; overrides as `--set` takes them. ConfigError names file,
    line and key."""

class ConfigResult:
    name: str
    algorithm: str
    estimate: Trajectory
    online: Trajectory
    mean_estimate: Trajectory
    run: EstimatorRun
    map_from_estimator: Pose2
    metrics: dict[str, float]
    nees: list[float]

class ScenarioResult:
    spec: ScenarioSpec
    passed: bool
    truth: Trajectory
    truth_map: Optional[OccupancyGrid]
    configs: dict[str, ConfigResult]
    sim_time_s: float
    scans: int
    scans_blacked_out: int
    notes: list[str]
    outcomes: list[dict]
    def write_report(self, out_dir: str) -> None: ...
    def expectation_table(self) -> str: ...

def run_scenario(spec: ScenarioSpec, view: bool = False,
                 progress: Optional[Callable[[float, float], None]] = None) -> ScenarioResult: ...

class PythonEstimator(Protocol):
    """What a Python estimator provides (only add_scan is required)."""
    def add_scan(self, scan: SyncedScan) -> Union[ScanEstimate, PoseLike, dict]: ...
    # Optional: add_record(record), record_estimate(), finish(), revised_poses() -> (N, 3),
    # map() -> OccupancyGrid | (log_odds[H, W], (x0, y0), resolution), statistics() -> dict,
    # loop_closures() -> [(from, to, pose)], particles() -> (N, 4).

def estimator_seed(run_seed: int, name: str) -> int:
    """The seed configuration `name` gets in a run seeded `run_seed` (what `seed=` receives)."""
