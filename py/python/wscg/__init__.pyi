from . import biometrics as biometrics
from . import cloth as cloth
from . import csmri as csmri
from . import deblur as deblur
from . import doe as doe
from . import ear as ear
from . import gait as gait
from . import hdr as hdr
from . import isosurface as isosurface
from . import math as math
from . import meshfilter as meshfilter
from . import motion as motion
from . import octree as octree
from . import raytrace as raytrace
from . import video as video
from . import volren as volren
from . import volseg as volseg

class IntegerRangeError(ValueError, OverflowError):
    """A negative or too large integer for a count, size or seed; names the argument."""

MAX_THREADS: int

def set_num_threads(n: int | None) -> None:
    """Sets the number of threads (1..1024; 0 or None: the default) of the pool that runs
    every wscg module in this process."""

def get_num_threads() -> int:
    """The number of threads of the pool that runs every wscg module in this process."""

__version__: str
__all__: list[str]
