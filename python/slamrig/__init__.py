"""slamrig from Python: simulate, read logs, run estimators (built-in or your own) and scenarios.

The classes and functions come from the C++ core (``slamrig._core``); arrays are NumPy views of
the C++ buffers wherever the owner can be kept alive (``LaserScan.ranges``, ``Trajectory.poses``,
``OccupancyGrid.log_odds``, ``Dataset.reference_poses``). An estimator written in Python is any
object with ``add_scan(scan) -> pose`` (and optionally ``add_record``, ``finish``, ``map``,
``revised_poses``, ``statistics``, ``particles``); name it in a scenario file
(``algorithm: python, module: my_pf, class: MyFilter``) or pass it with
``EstimatorConfig.python(name, MyFilter, **options)``.
"""

from ._core import *  # noqa: F401,F403
from ._core import ConfigError, ParseError  # noqa: F401

__all__ = [name for name in dir() if not name.startswith("_")]
