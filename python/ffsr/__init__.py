"""ffsr: capture-configuration optimization for free-floating space robots.

Python bindings (nanobind) over the C++ library of the same name, which implements Zhang,
"Configuration Optimization for Free-Floating Space Robot Capturing Tumbling Target",
Aerospace 9(2):69, 2022. SI units and radians; 6-vectors linear first; quaternions (x, y, z, w);
names as in C++. See docs/python.md.
"""

from ._ffsr import *  # noqa: F401,F403
from ._ffsr import __doc__ as _ext_doc  # noqa: F401

__version__ = "0.1.0"
