from ._core import *  # noqa: F401,F403
from ._core import ConfigError as ConfigError, ParseError as ParseError
