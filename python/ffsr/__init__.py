"""ffsr: capture-configuration optimization for free-floating space robots.

Python bindings (nanobind) over the C++ library of the same name, which implements Zhang,
"Configuration Optimization for Free-Floating Space Robot Capturing Tumbling Target",
Aerospace 9(2):69, 2022. SI units and radians; 6-vectors linear first; quaternions (x, y, z, w);
names as in C++. See docs/python.md.
"""

try:
    from ._ffsr import *  # noqa: F401,F403
    from ._ffsr import __doc__ as _ext_doc  # noqa: F401
    from . import _display

    _display.install()  # __repr__ and, for the jobs' results, _repr_html_ (the command's table)
except ImportError as _error:  # no compiled extension: ffsr.view still reads and checks the command's files
    _missing_extension = _error

    def __getattr__(name):  # AttributeError, so that `from ffsr import view` still finds the submodule
        raise AttributeError(f"ffsr.{name}: the compiled extension ffsr._ffsr is not available "
                             f"({_missing_extension}); only ffsr.view (the 3-D view of the command's --json and "
                             "--csv) works without it")

__version__ = "0.1.0"
