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
from . import distributed as distributed

class IntegerRangeError(ValueError, OverflowError):
    """A negative or too large integer for a count, size or seed; names the argument."""

class ArgumentTypeError(ValueError, TypeError):
    """An argument of the wrong kind for its parameter (``None`` where a value is required, a
    string or array where a number is, a complex array where real values are); names it."""

class NotFittedError(ValueError, AttributeError):
    """A method of an estimator that needs ``fit`` was called before it (also scikit-learn's
    ``NotFittedError`` when scikit-learn is imported)."""

class DataConversionWarning(UserWarning):
    """A column vector ``y`` ``(n, 1)`` was given where labels ``(n,)`` are expected."""

MAX_THREADS: int

def set_num_threads(n: int | None) -> None:
    """Sets the number of threads (1..1024; 0 or None: the default) of the pool that runs
    every wscg module in this process."""

def get_num_threads() -> int:
    """The number of threads of the pool that runs every wscg module in this process."""

def set_memory_limit(nbytes: int | None) -> None:
    """Sets the largest single buffer in bytes that a size argument may make wscg allocate
    (0 or None: the default, ``WSCG_MAX_MEMORY`` or the physical memory); larger requests
    raise ``MemoryError`` naming the argument."""

def get_memory_limit() -> int:
    """The largest single buffer in bytes that a size argument may make wscg allocate."""

def set_max_image_pixels(pixels: int | None) -> None:
    """Sets the largest width x height an image file may declare to be decoded (0 or None:
    the default, ``WSCG_MAX_IMAGE_PIXELS`` or 16384 x 16384); larger files raise
    ``ValueError`` before decoding."""

def get_max_image_pixels() -> int:
    """The largest width x height an image file may declare to be decoded."""

__version__: str
__all__ = ["biometrics", "cloth", "csmri", "deblur", "doe", "ear", "gait", "hdr", "isosurface",
           "math", "meshfilter", "motion", "octree", "raytrace", "video", "volren", "volseg",
           "distributed",
           "IntegerRangeError", "ArgumentTypeError", "NotFittedError", "DataConversionWarning",
           "set_num_threads", "get_num_threads", "set_memory_limit",
           "get_memory_limit", "set_max_image_pixels", "get_max_image_pixels", "__version__"]
