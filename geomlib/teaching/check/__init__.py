"""Exercise checks: ``geomlib.teaching.check.NAME(fn)`` runs a learner's function on small
cases with known answers and returns a ``CheckResult`` (``passed``, ``message``)
that names the first mistake found, with a hint and the derivation to reread.

One module per notebook holds its exercises' checks; ``result`` holds the
vocabulary they are written in.
"""

from .cotangent import *  # noqa: F401,F403
from .denoising import *  # noqa: F401,F403
from .explicit import *  # noqa: F401,F403
from .forms import *  # noqa: F401,F403
from .implicit import *  # noqa: F401,F403
from .result import CheckFailed, CheckResult, Mistake, reveal, use  # noqa: F401
from .spectral import *  # noqa: F401,F403
from .uniform import *  # noqa: F401,F403
