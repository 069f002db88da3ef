"""dmc: dynamic mesh codec (animated triangle meshes with fixed connectivity).

The codec, its distortion metrics, the Laplace operators and sequence I/O on NumPy arrays; the
functions live in the extension module dmc._dmc and are re-exported here. `python -m dmc.batch`
compresses many sequences on a Dask cluster (dmc/batch.py).
"""

from ._dmc import (  # noqa: F401  (the public API, re-exported)
    Error,
    ErrorCode,
    InternalError,
    InvalidArgumentError,
    IoError,
    NotFoundError,
    NumericalError,
    ParseError,
    ResourceLimitError,
    StreamError,
    UnsupportedError,
    __version__,
    decode,
    edit,
    encode,
    encoder_options,
    info,
    laplacian,
    methods,
    metrics,
    operators,
    read_sequence,
    set_simd_variant,
    simd_variant,
    simd_variants,
    synth,
    synth_names,
    write_sequence,
)
from ._dmc import __doc__ as _extension_doc

import difflib as _difflib
import functools as _functools
import inspect as _inspect


def _describe(value):
    """A short description of an argument: its type, and an array's dtype and shape."""
    shape, dtype = getattr(value, "shape", None), getattr(value, "dtype", None)
    if shape is not None and dtype is not None:
        return f"{type(value).__name__} {dtype} {tuple(shape)}"
    text = repr(value)
    return text if len(text) <= 40 else f"{type(value).__name__} of length {len(value)}" \
        if hasattr(value, "__len__") else type(value).__name__


def _with_readable_type_errors(function):
    """The extension's function behind a Python one with the same signature, whose TypeErrors
    name the parameters and describe the arguments (pybind11's print every array whole), and
    suggest the nearest keyword for a misspelt one."""
    signature = _inspect.signature(function)
    keywords = [p.name for p in signature.parameters.values()
                if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]

    @_functools.wraps(function)
    def call(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except TypeError as error:
            text = str(error)
            positional = [p.name for p in signature.parameters.values()
                          if p.kind == p.POSITIONAL_OR_KEYWORD][:len(args)]
            twice = [k for k in kwargs if k in positional]
            if twice:
                hint = (f"; a method parameter named like one of {function.__name__}()'s own "
                        f"arguments goes in parameters={{'{twice[0]}': ...}}"
                        if "parameters" in keywords else "")
                raise TypeError(f"{function.__name__}() got multiple values for argument "
                                f"'{twice[0]}'{hint}") from None
            unknown = [k for k in kwargs if k not in keywords]
            if "incompatible function arguments" not in text and not unknown:
                raise
            if unknown:
                parts = []
                for keyword in unknown:
                    near = _difflib.get_close_matches(keyword, keywords, n=1)
                    parts.append(f"'{keyword}'" + (f" (did you mean '{near[0]}'?)" if near else ""))
                message = (f"{function.__name__}() got an unexpected keyword argument "
                           + ", ".join(parts))
            else:
                given = ", ".join([_describe(a) for a in args]
                                  + [f"{k}={_describe(v)}" for k, v in kwargs.items()])
                message = (f"{function.__name__}{signature}: these arguments do not fit it: "
                           f"({given})")
            raise TypeError(message) from None

    call.__signature__ = signature
    return call


__all__ = [
    "Error",
    "ErrorCode",
    "InternalError",
    "InvalidArgumentError",
    "IoError",
    "NotFoundError",
    "NumericalError",
    "ParseError",
    "ResourceLimitError",
    "StreamError",
    "UnsupportedError",
    "__version__",
    "decode",
    "edit",
    "encode",
    "encoder_options",
    "info",
    "laplacian",
    "methods",
    "metrics",
    "operators",
    "read_sequence",
    "set_simd_variant",
    "simd_variant",
    "simd_variants",
    "synth",
    "synth_names",
    "write_sequence",
]
__doc__ = _extension_doc

# Every public function (the names of __all__ that are not classes or the version).
for _name in __all__:
    if callable(globals()[_name]) and not isinstance(globals()[_name], type):
        globals()[_name] = _with_readable_type_errors(globals()[_name])
del _name
