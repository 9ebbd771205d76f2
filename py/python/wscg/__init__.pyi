from . import biometrics as biometrics
from . import cloth as cloth
from . import math as math

__version__: str
__all__: list[str]
