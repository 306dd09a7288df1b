"""Rendering: one call for one image, a plan for many frames of one scene."""
import threading

from atmos._core import AtmosError, Owned, Progress, check, context, ffi, lib, number
from atmos.image import Image
from atmos.scene import Scene


def _to_srgb(ctx, spectral, wl):
    out = ffi.new("atmos_image **")
    check(lib.atmos_image_to_srgb(ctx, spectral, wl, out), ctx)
    return out[0]


# What Plan.render's camera dict may hold.
_CAMERA_KEYS = ("position_m", "look_at_m", "up", "fov_deg")


def _vector(where: str, value, n: int, integer: bool = False) -> list:
    """n numbers from a sequence, each checked as number() checks one."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != n:
        raise TypeError(f"atmos: {where}: expected {n} numbers, got {type(value).__name__} {value!r}")
    return [number(f"{where}[{i}]", v, integer) for i, v in enumerate(value)]


def _info(info, wl):
    return {"seconds": info.seconds, "sun_elevation_deg": info.sun_elevation_deg,
            "sun_azimuth_deg": info.sun_azimuth_deg, "wavelengths_nm": [wl.nm[k] for k in range(wl.count)]}


def _time_text(where: str, time) -> str:
    """An ISO 8601 time as the CLI's --time takes it, from a string or an aware datetime."""
    import datetime
    if isinstance(time, datetime.datetime):
        if time.tzinfo is None or time.utcoffset() is None:
            raise ValueError(f"atmos: {where}: time: a datetime without a time zone ({time.isoformat()}): "
                             "give tzinfo (datetime.timezone.utc) or a string ending in Z or +HH:MM")
        return time.astimezone(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%f")[:-3] + "Z"
    if not isinstance(time, str):
        raise TypeError(f"atmos: {where}: time: expected a string (\"2026-06-21T19:00Z\") or a datetime, "
                        f"got {type(time).__name__} {time!r}")
    return time


def _set_time(ctx, s, time, where: str) -> None:
    """Puts the sun of the scene s (a C scene, changed in place) where `time` puts it, as
    `atmos render --time` does: at the scene's place (its sun's latitude_deg and longitude_deg
    when the sun is given by time; over a round planet, the atmosphere's), with the scene's
    refraction; an animation by angles is dropped."""
    text = _time_text(where, time)
    t = ffi.new("atmos_utc_time *")
    pos = ffi.new("atmos_sun_position *")
    st = lib.atmos_parse_utc_time(ctx, text.encode(), t)
    if st == lib.ATMOS_OK:  # the years the solar position takes, as the CLI checks them
        st = lib.atmos_sun_position_compute(ctx, t, 0.0, 0.0, 0, pos)
    if st != lib.ATMOS_OK:
        raise AtmosError(st, f"atmos: {where}: time: " + ffi.string(lib.atmos_context_error(ctx)).decode(errors="replace"))
    if not s.sun.from_time:
        if s.atmosphere.kind not in (lib.ATMOS_ATMOSPHERE_DOBASHI, lib.ATMOS_ATMOSPHERE_SPHERICAL):
            raise ValueError(f"atmos: {where}: time {text!r}: the scene gives no place for the sun (a sun by angles "
                             "over a flat atmosphere): give it one, sun={\"time\": ..., \"latitude_deg\": ..., "
                             "\"longitude_deg\": ...}, as the CLI's --time needs --lat and --lon")
        s.sun.latitude_deg, s.sun.longitude_deg = s.atmosphere.latitude_deg, s.atmosphere.longitude_deg
    s.sun.time = t[0]
    s.sun.from_time = 1
    s.animation.elevation_end_set = s.animation.azimuth_end_set = 0


def _scene_at(ctx, s, time, frame, where: str):
    """The C scene s with the sun at `time` (_set_time) and then at frame `frame` of its
    animation (atmos_scene_animation_frame); s itself when neither is given."""
    if time is None and frame is None:
        return s
    out = ffi.new("atmos_scene *")
    ffi.memmove(out, s, ffi.sizeof("atmos_scene"))
    if time is not None:
        _set_time(ctx, out, time, where)
    if frame is not None:
        i = number(f"{where}: frame", frame, integer=True)
        fs = ffi.new("atmos_scene *")
        check(lib.atmos_scene_animation_frame(ctx, out, i, fs), ctx)
        out = fs
    return out


def render(scene: Scene | None = None, volume=None, *, time=None, frame=None, progress=None, **kw) -> Image:
    """Renders a scene as `atmos render` does (its renderer, settings, volume, atmosphere) and
    returns linear sRGB + alpha as an Image (``numpy.asarray`` gives ``(H, W, 4)`` float32,
    channels 0-2 equal to what ``atmos render --pfm`` writes). Keywords override the scene
    (``Scene.with_``). ``volume``: an ``atmos.Volume`` drawn instead of the scene's own, where
    its origin puts it (see ``Plan``); name a renderer for it here (``renderer="path"``), as a
    scene without a volume of its own cannot name a volume renderer. ``time``: the sun where
    this UTC time ("2026-06-21T19:00Z", or an aware datetime) puts it at the scene's place, as
    ``atmos render --time``; ``frame``: frame i (from 0) of the scene's animation, as ``atmos
    render --frames`` writes it; ``progress``: a callable(stage, fraction) called while the library
    works; returning False cancels (``atmos.Cancelled``), raising cancels with that exception.
    The GIL is released while the library renders."""
    scene = _as_scene(scene)
    if volume is not None:
        scene = _scene_for_volume(scene, kw)
    elif kw:
        scene = scene.with_(**kw)
    if volume is not None:
        with Plan(scene, volume, progress=progress) as plan:
            return plan.render(time=time, frame=frame, progress=progress)
    ctx = context()
    s = _scene_at(ctx, scene._struct(), time, frame, "render")
    spec = ffi.new("atmos_image **")
    info = ffi.new("atmos_render_info *")
    with Progress(progress, "render") as rep:
        framed = _frame(ctx, s, rep)
        st = lib.atmos_render_scene(ctx, s, framed if framed is not None else ffi.NULL, spec, info)
    rep.check(st, ctx)
    spec_img = ffi.gc(spec[0], lib.atmos_image_destroy)
    wl = ffi.new("atmos_wavelengths *")
    check(lib.atmos_scene_wavelengths(ctx, s, wl), ctx)
    rgb = _to_srgb(ctx, spec_img, wl)
    ffi.release(spec_img)
    return Image(rgb, _info(info, wl))


def _as_scene(scene) -> Scene:
    if scene is None:
        return Scene.default()
    if not isinstance(scene, Scene):
        raise TypeError(f"atmos: expected an atmos.Scene (atmos.Scene.load(path) for a file), got {type(scene).__name__}")
    return scene


def _frame(ctx, s, rep):
    """A scene naming a volume file and no camera is framed as `atmos render` frames it
    (atmos_scene_frame_volume_file): the loaded volume, or None when there was nothing to frame.
    rep: the call's Progress."""
    vol = ffi.new("atmos_volume **")
    rep.check(lib.atmos_scene_frame_volume_file(ctx, s, float("nan"), vol), ctx)
    return ffi.gc(vol[0], lib.atmos_volume_destroy) if vol[0] != ffi.NULL else None


def _scene_for_volume(scene: Scene, kw=None) -> Scene:
    """A scene that renders a volume given in code, with the keywords kw: one without a
    "volume" of its own is given a stand-in source (never read: the given volume is used), so
    that it is validated, and drawn by default, as a scene with a volume."""
    try:
        if not ffi.string(scene._struct().volume.source):
            scene = scene.with_(volume__generate="cumulus")
        return scene.with_(**kw) if kw else scene
    except AtmosError as e:  # said of the volume given, not of the stand-in's keyword
        msg = e.message.split(": ", 2)[-1] if "volume__generate" in e.message else e.message
        raise AtmosError(e.status, f"the volume given: {msg}") from None


class Plan(Owned):
    """A plan: the scene's atmosphere, volume, optics and renderer state made once; each
    ``render(camera=..., sun=...)`` does only the work its changes need (a moved sun does not
    resample the volume; the path tracer adds samples while nothing moves). ``volume``: an
    ``atmos.Volume`` drawn instead of the scene's own, at the place its origin gives (not
    moved by the scene's placement rules); the scene's "volume" settings (particle, density
    scale) still apply, and a scene without one renders it with the slice renderer unless it
    names another. ``progress``: as ``render``'s, for the plan's making (tables, the volume).

    >>> with atmos.Plan(scene) as plan:
    ...     for az in range(0, 360, 10):
    ...         img = plan.render(sun=(20, az))
    ...     for img in plan.frames():   # the scene's animation, as atmos render --frames
    ...         ...
    """

    def __init__(self, scene: Scene, volume=None, progress=None):
        scene = _as_scene(scene)
        ctx = context()
        desc = ffi.NULL
        if volume is not None:
            scene = _scene_for_volume(scene)
            desc = ffi.new("atmos_plan_desc *")
            desc.offset_given = 1  # the volume stays where its origin puts it
        self._scene = scene._struct()
        p = ffi.new("atmos_plan **")
        with Progress(progress, "Plan") as rep:
            vptr = volume._live() if volume is not None else _frame(ctx, self._scene, rep)
            self._volume = vptr  # borrowed by the plan: kept alive with it
            st = lib.atmos_plan_create(ctx, self._scene, vptr if vptr is not None else ffi.NULL, desc, p)
        rep.check(st, ctx)
        self._ptr = ffi.gc(p[0], lib.atmos_plan_destroy)
        if volume is not None:
            volume._plans.add(self)  # its close() refused while this plan is open
        self._ctx = ctx  # the plan's own: its errors are told there, whichever thread renders
        # one render at a time (a plan is not for two at once), and close() waits for it, or, from
        # within it (a progress callback), takes effect when it returns
        self._lock, self._busy, self._close_pending = threading.RLock(), 0, False
        self._frame = ffi.new("atmos_frame *")
        check(lib.atmos_frame_from_scene(ctx, self._scene, self._frame), ctx)

    def close(self) -> None:
        """Frees the plan now; from another thread while it renders, once that render is done;
        from within a render (its progress callback), when the render returns."""
        with self._lock:
            if self._busy:
                self._close_pending = True
            else:
                Owned.close(self)

    @property
    def frame_count(self) -> int:
        """The frames of the scene's animation (1 without one)."""
        return max(1, self._scene.animation.frames)

    def frames(self, progress=None):
        """The scene's animation, frame after frame (``render(frame=i)`` for each i): the images
        ``atmos render --frames`` writes."""
        for i in range(self.frame_count):
            yield self.render(frame=i, progress=progress)

    def render(self, camera: dict | None = None, sun=None, size=None, spp=None, *, time=None, frame=None,
               progress=None) -> Image:
        """Renders a frame. camera: {"position_m": [x, y, z], "look_at_m": [...], "fov_deg": f}
        (any subset); sun: (elevation_deg, azimuth_deg); time: the sun where this UTC time
        ("2026-06-21T19:00Z", or an aware datetime) puts it at the scene's place (as ``atmos render
        --time``); frame: the sun of frame i (from 0) of the scene's animation (from ``time`` if
        given too); size: (width, height); spp: the path tracer's samples per pixel; progress: as
        ``atmos.render``'s. What is not given stays as in the last frame rendered: a call that
        fails changes nothing. Calls from several threads take turns."""
        with self._lock:
            if self._ptr is None or self._close_pending:
                raise ValueError("atmos.Plan: the plan was closed")
            self._busy += 1
            try:
                return self._render(camera, sun, size, spp, time, frame, progress)
            finally:
                self._busy -= 1
                if self._close_pending and not self._busy:
                    Owned.close(self)

    def _render(self, camera, sun, size, spp, time, frame, progress) -> Image:
        # the changes go to a copy, kept as the plan's frame once the render succeeded: a call
        # that fails leaves the next one the frame before it
        f = ffi.new("atmos_frame *")
        ffi.memmove(f, self._frame, ffi.sizeof("atmos_frame"))
        w = "Plan.render"
        if camera:
            unknown = sorted(str(k) for k in camera if k not in _CAMERA_KEYS)
            if unknown:  # as a scene's unknown key is refused
                raise ValueError(f"atmos: {w}: camera: unknown key {unknown[0]!r} "
                                 f"(known: {', '.join(_CAMERA_KEYS)})")
            for key, field in (("position_m", "position"), ("look_at_m", "look_at"), ("up", "up")):
                if key in camera:
                    setattr(f.camera, field, _vector(f"{w}: camera {key}", camera[key], 3))
            if "up" in camera and not any(f.camera.up[i] for i in range(3)):  # 0 would keep the last frame's
                raise ValueError(f"atmos: {w}: camera up: must not be zero")
            if "fov_deg" in camera:
                f.camera.fov_deg = number(f"{w}: camera fov_deg", camera["fov_deg"])
                if not f.camera.fov_deg > 0:  # 0 would keep the last frame's
                    raise ValueError(f"atmos: {w}: camera fov_deg: must be > 0, got {f.camera.fov_deg:g}")
        if sun is not None:
            el, az = _vector(f"{w}: sun (elevation_deg, azimuth_deg)", sun, 2)
            if not -90.0 <= el <= 90.0:  # as the scene's sun.elevation_deg (else wrapped past a pole)
                raise ValueError(f"atmos: {w}: sun elevation_deg: {el:g} is not in [-90, 90]")
            if not 0.0 <= az < 360.0:  # as the scene's sun.azimuth_deg and the CLI's azimuths
                raise ValueError(f"atmos: {w}: sun azimuth_deg: {az:g} is not in [0, 360)")
            lib.atmos_direction_from_angles(el, az, f.sun_dir)
        ctx = self._ctx
        if time is not None or frame is not None:
            if sun is not None:
                raise ValueError(f"atmos: {w}: sun (angles) and time or frame exclude each other")
            if frame is not None and self._scene.animation.minutes_end_set:
                raise ValueError(f"atmos: {w}: frame: the scene's animation is a time-lapse (a volume a frame, "
                                 "\"minutes_end\"), which one plan does not render: atmos.render(scene, frame=i)")
            fs = _scene_at(ctx, self._scene, time, frame, w)
            check(lib.atmos_scene_sun_direction(ctx, fs, f.sun_dir, ffi.NULL, ffi.NULL), ctx)
        if size is not None:
            f.width, f.height = _vector(f"{w}: size (width, height)", size, 2, integer=True)
        if spp is not None:
            f.spp = number(f"{w}: spp", spp, integer=True)
            if not 1 <= f.spp <= 1000000:  # 0 would keep the last frame's
                raise ValueError(f"atmos: {w}: spp: must be in [1, 1000000], got {spp}")
        img = ffi.new("atmos_image **")
        check(lib.atmos_plan_image_create(self._ptr, f, img), ctx)
        spec = ffi.gc(img[0], lib.atmos_image_destroy)
        info = ffi.new("atmos_render_info *")
        with Progress(progress, w) as rep:
            st = lib.atmos_plan_render(self._ptr, f, ffi.NULL, spec, info)
        rep.check(st, ctx)
        wl = lib.atmos_plan_wavelengths(self._ptr)
        rgb = _to_srgb(ctx, spec, wl)
        ffi.release(spec)
        self._frame = f
        return Image(rgb, _info(info, wl))

    def __repr__(self):
        return "<atmos.Plan closed>" if self._ptr is None else f"<atmos.Plan {self._frame.width}x{self._frame.height}>"
