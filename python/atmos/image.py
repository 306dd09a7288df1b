"""Images: an atmos image seen by NumPy without a copy, and an image file's kind."""
import os

import numpy as np

from atmos._core import Owned, check, context, ffi, lib


def _path(where: str, path) -> bytes:
    """A file name (str, bytes or os.PathLike) as the library takes it; anything else (None) a
    TypeError naming `where` (str(path) made None the file "None")."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"atmos: {where}: expected a file name (str, bytes or os.PathLike), "
                        f"got {type(path).__name__}")
    name = os.fsencode(path)
    if b"\0" in name:  # the library would read the name only up to it, past the suffix's check
        raise ValueError(f"atmos: {where}: a file name with a NUL byte: {path!r}")
    return name


class Image(Owned):
    """An image the library made: ``height x width`` pixels of ``channels`` float32 values,
    row-major, top row first. ``numpy.asarray(image)`` is a ``(height, width, channels)``
    float32 view of the library's own buffer (no copy; the array keeps the image alive).

    Rendered images hold linear sRGB (Rec. 709 primaries, D65; Y in cd/m^2) and coverage alpha:
    channels 0-2 are what ``atmos render --pfm`` writes. ``meta`` holds the image's metadata
    (scene, renderer, sun, camera: the library's atmos:* keys, and the render's time) as a
    dict of strings; ``channels`` names the channels. ``close()`` (or ``with``) frees it at once;
    arrays made from it must not be used afterwards."""

    def __init__(self, ptr, meta=None, channels=None):
        self._ptr = ffi.gc(ptr, lib.atmos_image_destroy)
        self.meta = {ffi.string(ptr.meta[i].key).decode(errors="replace"): ffi.string(ptr.meta[i].value).decode(errors="replace")
                     for i in range(ptr.meta_count)}
        self.meta.update(meta or {})
        self.channels = list(channels) if channels else (["R", "G", "B", "A"][: ptr.channels] if ptr.channels in (3, 4)
                                                         else [f"C{i}" for i in range(ptr.channels)])

    @property
    def shape(self):
        p = self._live()
        return (p.height, p.width, p.channels)

    def _live(self):
        if self._ptr is None:
            raise ValueError("atmos.Image: the image was closed")
        return self._ptr

    @property
    def __array_interface__(self):
        p = self._live()
        return {
            "shape": (p.height, p.width, p.channels),
            "typestr": "<f4",
            "data": (int(ffi.cast("uintptr_t", p.pixels)), False),
            "version": 3,
        }

    def numpy(self) -> np.ndarray:
        """The pixels as a ``(height, width, channels)`` float32 array sharing this image's memory."""
        return np.asarray(self)

    def write_exr(self, path: str) -> None:
        """Writes the image as OpenEXR (linear, atomically); the name must end in .exr."""
        name = _path("Image.write_exr", path)
        if not name.lower().endswith(b".exr"):
            raise ValueError(f"atmos.Image.write_exr: {path}: an OpenEXR file's name ends in .exr")
        check(lib.atmos_write_exr(context(), self._live(), name, ffi.NULL))

    def write_pfm(self, path: str) -> None:
        """Writes the first three channels as a portable float map (atomically); the name must end in .pfm."""
        name = _path("Image.write_pfm", path)
        if not name.lower().endswith(b".pfm"):
            raise ValueError(f"atmos.Image.write_pfm: {path}: a portable float map's name ends in .pfm")
        check(lib.atmos_write_pfm(context(), self._live(), name))

    def __repr__(self):
        if self._ptr is None:
            return "<atmos.Image closed>"
        h, w, c = self.shape
        return f"<atmos.Image {w}x{h}, {c} channels, float32>"


def read_exr(path) -> Image:
    """Reads an OpenEXR file (any channel count: an ``atmos render --exr-layers`` file's
    R, G, B, A, tau.Y, ...), with its channel names in ``channels`` and its attributes in
    ``meta``."""
    ctx = context()
    out = ffi.new("atmos_image **")
    names = ffi.new("char ***")
    check(lib.atmos_read_exr_named(ctx, _path("read_exr", path), out, names), ctx)
    n = out[0].channels
    chans = [ffi.string(names[0][i]).decode() for i in range(n)]
    lib.free(names[0])
    return Image(out[0], channels=chans)


def _kind(p) -> str | None:
    return None if p == ffi.NULL else ffi.string(p).decode()


def image_kind(data) -> str | None:
    """An image's format by its first bytes (``bytes``, ``bytearray`` or ``memoryview``), as the
    readers tell it: "OpenEXR", "PNG", "JPEG" or "PFM", else None (``atmos_image_kind``)."""
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise TypeError(f"atmos: image_kind: expected bytes, got {type(data).__name__}")
    b = bytes(data[:8])  # the longest magic number the readers test (PNG's)
    return _kind(lib.atmos_image_kind(ffi.from_buffer(b), len(b)))


def image_file_kind(path) -> str | None:
    """A file's image format by its first 8 bytes, as ``image_kind`` tells it; None also when
    the file cannot be read (``atmos_image_file_kind``)."""
    return _kind(lib.atmos_image_file_kind(_path("image_file_kind", path)))
