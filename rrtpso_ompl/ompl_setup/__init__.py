"""TODO"""

from .context import *  # noqa: F403
from .context import __all__  # noqa: F401
