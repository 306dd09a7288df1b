"""The native module, atmos's errors as exceptions, and one context per thread."""
import re
import threading



def _import_error(missing, cause):
    """The ImportError of an interpreter that cannot load the package: which interpreter
    the build was for (CMake's choice, python/atmos/_build_info.py), which this is, and
    what it lacks."""
    import sys
    try:
        from atmos._build_info import PYTHON as built
    except ImportError:
        built = None
    this = f"{sys.executable} (Python {sys.version.split()[0]})"
    where = (f"built for {built} (cmake/python.cmake chose it; CMake prints it when configuring)"
             if built else "built by pip for the interpreter that ran it")
    if missing:
        what = f"this interpreter, {this}, lacks {' and '.join(missing)}"
    else:
        what = (f"the native module cannot be loaded by {this} (not built: run `make build` in the "
                f"checkout, or `pip install ./python` against an installed atmos; or built for "
                f"another Python version) ({cause})")
    fix = (f"run it with {built}, or configure with -DATMOS_PYTHON={sys.executable} once this "
           f"interpreter has cffi and NumPy" if built else "install cffi and NumPy and reinstall")
    return ImportError(f"atmos: {what}; the package was {where}: {fix}")


def _missing():
    missing = []
    for module, package in (("numpy", "numpy"), ("_cffi_backend", "cffi")):
        try:
            __import__(module)
        except ImportError:
            missing.append(package)
    return missing


try:
    from atmos._native import ffi, lib
except ImportError as e:  # pragma: no cover - the message is the point
    raise _import_error(_missing(), e) from e
if _missing():  # pragma: no cover - NumPy is imported by the modules after this one
    raise _import_error(_missing(), None)

STATUS_NAMES = {
    lib.ATMOS_E_INVALID_ARG: "invalid argument",
    lib.ATMOS_E_NOMEM: "out of memory",
    lib.ATMOS_E_IO: "I/O error",
    lib.ATMOS_E_FORMAT: "malformed file",
    lib.ATMOS_E_UNSUPPORTED: "unsupported",
    lib.ATMOS_E_LIMIT: "limit exceeded",
    lib.ATMOS_E_CANCELLED: "cancelled",
}


class AtmosError(RuntimeError):
    """A failed atmos call: ``status`` is atmos's status code (``atmos_status``), ``message``
    the library's own message (naming the file, key or value at fault)."""

    def __init__(self, status: int, message: str):
        self.status = int(status)
        self.message = message
        super().__init__(f"{message} ({STATUS_NAMES.get(self.status, 'error')}, status {self.status})")


class Cancelled(AtmosError):
    """An AtmosError for a render stopped by its progress callback (status 7, cancelled): the
    callback returned False. A callback that raised stops the render with its own exception."""


class AtmosTypeError(AtmosError, TypeError):
    """An AtmosError for a scene value of the wrong type ("expected a number, got a string"):
    also a TypeError, as the package's own checks of arguments raise."""


_local = threading.local()


@ffi.def_extern()
def atmos_py_progress(user, stage, fraction):
    """Every context's progress reports, while the calling thread's current call has a
    callback (the C sink passes them on only then): to that callback."""
    rep = getattr(_local, "progress", None)
    return rep.report(stage, fraction) if rep is not None else 0


class Progress:
    """The progress callback of one call into the library (``with Progress(callback, where) as
    p: status = lib.atmos_...; p.check(status, ctx)``): the callback receives (stage, fraction);
    returning False, or raising, cancels the call, which then raises Cancelled, or the
    callback's own exception."""

    def __init__(self, callback, where: str):
        if callback is not None and not callable(callback):
            raise TypeError(f"atmos: {where}: progress: expected a callable (stage, fraction), "
                            f"got {type(callback).__name__}")
        self._callback, self._where = callback, where
        self._prev, self._was_on, self.error, self.stopped = None, 0, None, False

    def __enter__(self):
        self._prev = getattr(_local, "progress", None)
        _local.progress = self if self._callback is not None else None
        self._was_on = lib.atmos_py_progress_swap(self._callback is not None)
        return self

    def __exit__(self, *exc):
        lib.atmos_py_progress_swap(self._was_on)
        _local.progress = self._prev

    def report(self, stage, fraction) -> int:
        if self.stopped:  # asked once: every later report asks again
            return 1
        try:
            said = self._callback(ffi.string(stage).decode(errors="replace"), float(fraction))
            self.stopped = said is not None and not said  # its truth may raise too (a NumPy array)
        except BaseException as e:  # noqa: BLE001 - raised again once the library has returned
            self.error = e
            self.stopped = True
        return 1 if self.stopped else 0

    def check(self, status: int, ctx=None) -> None:
        """check(status, ctx), the callback's exception first: raised when the callback raised,
        even if the library finished anyway."""
        if self.error is not None:
            e, self.error = self.error, None
            raise e
        if status == lib.ATMOS_E_CANCELLED and self.stopped:
            ctx = ctx if ctx is not None else context()
            msg = ffi.string(lib.atmos_context_error(ctx)).decode(errors="replace")
            raise Cancelled(status, f"{self._where}: {msg} (the progress callback returned False)")
        check(status, ctx)


def context():
    """This thread's atmos context (created on first use, all cores, the default cache), with
    the package's progress sink (Progress). A context is not shared between threads, so
    several threads may render at once."""
    ctx = getattr(_local, "ctx", None)
    if ctx is None:
        p = ffi.new("atmos_context **")
        st = lib.atmos_py_context_create(p)  # the defaults, with the progress sink
        if st != lib.ATMOS_OK:
            raise AtmosError(st, ffi.string(lib.atmos_status_string(st)).decode())
        ctx = ffi.gc(p[0], lib.atmos_context_destroy)
        _local.ctx = ctx
    return ctx


def check(status: int, ctx=None, types: bool = False) -> None:
    """Raises AtmosError with the context's message unless status is ATMOS_OK; with types, an
    AtmosTypeError when the message is the scene reader's about a value's type ("/camera/fov_deg:
    expected a number, got a string")."""
    if status != lib.ATMOS_OK:
        ctx = ctx if ctx is not None else context()
        msg = ffi.string(lib.atmos_context_error(ctx)).decode(errors="replace")
        if status == lib.ATMOS_E_CANCELLED:
            raise Cancelled(status, msg)
        if types and status == lib.ATMOS_E_INVALID_ARG and re.search(r": expected an? [^,]+, got an? [a-z ]+$", msg):
            raise AtmosTypeError(status, msg)
        raise AtmosError(status, msg)


def version() -> str:
    """The library's version, "MAJOR.MINOR.PATCH"."""
    return ffi.string(lib.atmos_version()).decode()


class Owned:
    """An object holding one library object in ``_ptr`` (a cffi pointer with its destructor):
    ``close()`` frees it at once, ``with`` closes it at the block's end, and collection
    frees it otherwise."""

    _ptr = None

    def close(self) -> None:
        """Frees the library object now."""
        if self._ptr is not None:
            ffi.release(self._ptr)
            self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def number(where: str, value, integer: bool = False):
    """value as a finite float (an int with integer=True) for the argument `where`: a
    TypeError naming its type when it is not a number (bool included), a ValueError when it
    is NaN or infinite (or not whole with integer=True)."""
    import math
    import numbers
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"atmos: {where}: expected a number, got {type(value).__name__} {value!r}")
    f = float(value)
    if not math.isfinite(f):
        raise ValueError(f"atmos: {where}: {f} is not a finite number")
    if integer:
        if f != int(f):
            raise ValueError(f"atmos: {where}: expected a whole number, got {value!r}")
        return int(f)
    return f


def json_value(where: str, value):
    """value as plain JSON data (NumPy scalars and arrays as numbers and lists), checked on
    the way: NaN and infinities, which JSON cannot carry (the library would read them as words),
    raise a ValueError naming where they are; values of other types a TypeError."""
    import math
    if hasattr(value, "tolist"):
        value = value.tolist()
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"atmos: {where}: {value} is not a finite number")
        return value
    if isinstance(value, (list, tuple)):
        return [json_value(f"{where}[{i}]", v) for i, v in enumerate(value)]
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"atmos: {where}: a key must be a string, got {type(k).__name__} {k!r}")
            out[k] = json_value(f"{where}.{k}" if where else k, v)
        return out
    raise TypeError(f"atmos: {where}: expected a JSON value (number, string, bool, list or dict), "
                    f"got {type(value).__name__}")
