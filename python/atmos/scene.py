"""Scenes: a scene file, a dict or the built-in default, with overrides as the CLI's -D."""
import json
import os

from atmos._core import AtmosError, check, context, ffi, json_value, lib

# Keyword arguments with a name of their own (as the CLI's options); any other keyword is a
# path into the scene with "__" between keys: camera__fov_deg=35 is -D camera.fov_deg=35.
_SHORT = {
    "width": "image.width",
    "height": "image.height",
    "spp": "path.spp",
    "renderer": "renderer",
    "sun_elevation_deg": "sun.elevation_deg",
    "sun_azimuth_deg": "sun.azimuth_deg",
    "samples_per_pixel": "image.samples_per_pixel",
}


def _dumps(where: str, value) -> str:
    """value as JSON text; NaN, infinities and other types refused naming where they are
    (json.dumps would write NaN as a bare word, which the library reads as a string)."""
    return json.dumps(json_value(where, value), allow_nan=False)


def _override(key: str, value) -> str:
    path = _SHORT.get(key, key.replace("__", "."))
    return f"{path}={_dumps(path, value)}"


def _as_keywords(e: AtmosError, said: dict) -> AtmosError:
    """e with a keyword argument named as the caller wrote it: the library blames a mistake at a
    key an override set on the CLI's spelling, "-D image.width=-1 (on default): ..."."""
    msg = e.message
    for ov, kw in said.items():
        prefix = f"-D {ov} (on "
        if msg.startswith(prefix):
            msg = f"keyword argument {kw} (on " + msg[len(prefix):]
            break
    return type(e)(e.status, msg)


class Scene:
    """A scene as atmos reads it: a JSON document (docs/scene-format.md) from a file, a dict
    or the built-in default, plus overrides. It is parsed and validated by the library, so
    a bad key or value raises AtmosError naming it, as the CLI does.

    >>> s = atmos.Scene.load("scenes/fig11_cumulus_dawn.json")
    >>> s2 = s.with_(width=320, height=200, camera__fov_deg=35)
    """

    def __init__(self, text: str = "{}", path: str | None = None, overrides=(), source: str = "scene", said=None):
        self._text = text
        self._path = path
        self._overrides = tuple(overrides)
        self._source = source
        self._said = dict(said or {})  # override -> the keyword argument that made it, for messages
        self._struct()  # validate now: errors belong to the line that made the scene

    @classmethod
    def default(cls) -> "Scene":
        """The built-in default scene (what `atmos render` renders without a scene file)."""
        return cls("{}", source="default")

    @classmethod
    def load(cls, path) -> "Scene":
        """Reads a scene file; relative volume paths are taken from the file's folder."""
        path = os.fspath(path)
        if not isinstance(path, str) or "\0" in path:  # C would read the path up to the NUL
            raise ValueError(f"atmos: Scene.load: path: expected a file name without NUL, got {path!r}")
        return cls(path=path, source=path)

    @classmethod
    def from_dict(cls, d: dict, source: str = "dict") -> "Scene":
        """A scene from a dict with the scene file's keys."""
        if not isinstance(d, dict):
            raise TypeError(f"atmos.Scene.from_dict: expected a dict, got {type(d).__name__}")
        return cls(_dumps("", d), source=source)

    @classmethod
    def from_json(cls, text: str, source: str = "json") -> "Scene":
        return cls(text, source=source)

    def with_(self, **kw) -> "Scene":
        """A copy with keys overridden: width, height, spp, renderer, sun_elevation_deg,
        sun_azimuth_deg, samples_per_pixel by name; any other key as a path with "__"
        between its parts (camera__position_m=[0, 900, 0])."""
        extra = tuple(_override(k, v) for k, v in kw.items())
        said = {**self._said, **{o: f"{k}={v!r}" for o, (k, v) in zip(extra, kw.items())}}
        return Scene(self._text, self._path, self._overrides + extra, self._source, said)

    def _struct(self):
        """The validated C scene (a new atmos_scene each call)."""
        ctx = context()
        out = ffi.new("atmos_scene *")
        keep = [ffi.new("char[]", o.encode()) for o in self._overrides]
        arr = ffi.new("const char *[]", keep) if keep else ffi.NULL
        if self._path is not None:
            st = lib.atmos_scene_load_with(ctx, self._path.encode(), arr, len(keep), out)
        else:
            raw = self._text.encode()
            st = lib.atmos_scene_parse_with(ctx, raw, len(raw), self._source.encode(), arr, len(keep), out)
        try:
            check(st, ctx, types=True)
        except AtmosError as e:
            raise _as_keywords(e, self._said) from None
        return out

    @property
    def wavelengths_nm(self):
        """The scene's wavelengths in nm: what the K of render images and sky_radiance are."""
        ctx = context()
        wl = ffi.new("atmos_wavelengths *")
        check(lib.atmos_scene_wavelengths(ctx, self._struct(), wl), ctx)
        return [wl.nm[k] for k in range(wl.count)]

    @property
    def size(self):
        """(width, height) in pixels."""
        s = self._struct()
        return (s.width, s.height)

    def __repr__(self):
        where = self._path or self._source
        extra = f", {len(self._overrides)} override(s)" if self._overrides else ""
        w, h = self.size
        return f"<atmos.Scene {where!r} {w}x{h}{extra}>"
