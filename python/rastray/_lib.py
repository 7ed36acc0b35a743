"""Loads librastray through cffi (ABI mode: no compiler needed).

The declarations are read from rastray.h at import, so they cannot drift from the
library: comments and preprocessor lines are dropped, RR_API erased and the header's
integer #defines substituted (cffi's parser knows no macros).

Where the files are found, first match wins:
  library: $RASTRAY_LIBRARY, the package's own directory, the build trees ../build
           and ../build-* beside python/, then the system's (ctypes.util.find_library);
  header:  $RASTRAY_HEADER, ../include/rastray.h beside python/, then include/
           beside the library's lib/ directory (an installed prefix).
"""
import ctypes.util
import glob
import os
import re

import cffi

_here = os.path.dirname(os.path.abspath(__file__))
_root = os.path.dirname(os.path.dirname(_here))  # the source tree, when run from it


def _find_library():
    env = os.environ.get("RASTRAY_LIBRARY")
    if env:
        return env
    candidates = sorted(glob.glob(os.path.join(_here, "librastray.so*")))
    for build in ["build"] + sorted(os.path.basename(p) for p in glob.glob(os.path.join(_root, "build-*"))):
        candidates += sorted(glob.glob(os.path.join(_root, build, "librastray.so")))
    for c in candidates:
        if os.path.exists(c):
            return c
    found = ctypes.util.find_library("rastray")
    if found:
        return found
    raise ImportError("rastray: librastray.so not found; build it (cmake --build build) or set RASTRAY_LIBRARY")


def _find_header(library):
    env = os.environ.get("RASTRAY_HEADER")
    candidates = [env] if env else []
    candidates += [os.path.join(_here, "rastray.h"), os.path.join(_root, "include", "rastray.h")]
    libdir = os.path.dirname(os.path.realpath(library)) if os.path.sep in library else ""
    if libdir:
        candidates += [os.path.join(os.path.dirname(libdir), "include", "rastray.h"),
                       os.path.join(os.path.dirname(os.path.dirname(libdir)), "include", "rastray.h")]
    candidates += ["/usr/local/include/rastray.h", "/usr/include/rastray.h"]
    for c in candidates:
        if c and os.path.exists(c):
            return c
    raise ImportError("rastray: rastray.h not found; set RASTRAY_HEADER")


def cdef_from_header(text):
    """The declarations of rastray.h as cffi's cdef takes them, and its integer #defines."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    consts = {}
    for name, value in re.findall(r"^\s*#\s*define\s+(RR_\w+)\s+(0x[0-9A-Fa-f]+|\d+)[uU]?\s*$", text, flags=re.M):
        consts[name] = int(value, 0)
    text = re.sub(r"#\s*ifdef\s+__cplusplus.*?#\s*endif", " ", text, flags=re.S)  # extern "C" { and }
    lines = [l for l in text.split("\n") if not l.lstrip().startswith("#")]
    body = "\n".join(lines).replace("RR_API", "")
    for name, value in consts.items():
        body = re.sub(r"\b%s\b" % name, str(value), body)
    return body, consts


ffi = cffi.FFI()
LIBRARY = _find_library()
HEADER = _find_header(LIBRARY)
with open(HEADER, encoding="utf-8") as f:
    _cdef, CONSTANTS = cdef_from_header(f.read())
ffi.cdef(_cdef)
lib = ffi.dlopen(LIBRARY)
