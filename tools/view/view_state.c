/* The viewer's state and what the actions do to it (view.h). World frame: y up, north -z,
 * east +x; azimuths clockwise from north (atmos_direction_from_angles). */
#include "view.h"

#include <math.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)

static double clampd(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

static double wrap360(double a)
{
    a = fmod(a, 360.0);
    return a < 0 ? a + 360.0 : a;
}

void view_state_forward(const view_state *s, double d[3])
{
    atmos_direction_from_angles(s->pitch_deg, s->yaw_deg, d);
}

void view_state_up(const view_state *s, double u[3])
{
    /* the forward direction turned 90 degrees up in its vertical plane: at pitch < 90 the
     * world's up made perpendicular to the view (what atmos_camera_init does with (0, 1, 0)),
     * at pitch 90 the heading's opposite, as when one tilts one's head back */
    const double p = s->pitch_deg * DEG, y = s->yaw_deg * DEG;
    u[0] = -sin(p) * sin(y), u[1] = cos(p), u[2] = sin(p) * cos(y);
}

int view_renderer_draws(atmos_renderer_kind r, atmos_camera_type t)
{
    /* the library's rules: src/render/plan.c (slice), src/scene/scene_lights.c (beams); Harris's
     * splats take every camera (src/particles/psplat.c) */
    return t == ATMOS_CAMERA_PINHOLE || !(r == ATMOS_RENDERER_SLICE || r == ATMOS_RENDERER_BEAMS);
}

atmos_camera_type view_state_camera(const view_state *s, double *fov_deg)
{
    const int kept = view_renderer_draws(s->renderer, s->camera);
    if (fov_deg) *fov_deg = kept ? s->fov_deg : s->pinhole_fov_deg;
    return kept ? s->camera : ATMOS_CAMERA_PINHOLE;
}

double view_state_pitch_limit(const view_state *s)
{
    return s->camera == ATMOS_CAMERA_PINHOLE ? 89.0 : 90.0;
}

void view_state_sun(view_state *s)
{
    if (!s->sun_from_time) return;
    atmos_sun_position p;
    if (atmos_sun_position_compute(NULL, &s->time, s->lat, s->lon, 1, &p) == ATMOS_OK) {
        s->sun_el = p.elevation_deg;
        s->sun_az = p.azimuth_deg;
    }
}

/* The view's pitch and yaw of the scene's camera c, its defaults resolved (camera.h) by
 * atmos_camera_init; looking straight up or down, the yaw is the one whose image up
 * (view_state_up) is the camera's. An equirect's directions are those of a pinhole's. */
static void orientation(const atmos_camera_desc *c, double *pitch, double *yaw)
{
    atmos_camera_desc d = *c;
    if (d.type == ATMOS_CAMERA_EQUIRECT) d.type = ATMOS_CAMERA_PINHOLE, d.fov_deg = 60.0;
    atmos_camera cam;
    if (atmos_camera_init(NULL, &d, 16, 16, &cam) != ATMOS_OK) { /* the scene was validated: never */
        *pitch = 0.0, *yaw = 0.0;
        return;
    }
    atmos_direction_to_angles(cam.forward, pitch, yaw);
    if (fabs(cam.forward[1]) > 0.99999) {
        double el, up_az;
        atmos_direction_to_angles(cam.up, &el, &up_az);
        *pitch = cam.forward[1] > 0 ? 90.0 : -90.0;
        *yaw = wrap360(up_az + (cam.forward[1] > 0 ? 180.0 : 0.0));
    }
}

void view_state_init(view_state *s, const atmos_scene *sc, const atmos_frame *f, const double *target)
{
    memset(s, 0, sizeof *s);
    memcpy(s->pos, f->camera.position, sizeof s->pos);
    s->camera = f->camera.type;
    orientation(&f->camera, &s->pitch_deg, &s->yaw_deg);
    const double limit = view_state_pitch_limit(s);
    s->pitch_deg = clampd(s->pitch_deg, -limit, limit);
    /* the type's default for 0 (camera.h); an equirect's is unused */
    s->fov_deg = f->camera.fov_deg > 0 && s->camera != ATMOS_CAMERA_EQUIRECT ? f->camera.fov_deg
                 : s->camera == ATMOS_CAMERA_PINHOLE                          ? 60.0
                                                                              : 180.0;
    s->pinhole_fov_deg = fmin(s->fov_deg, 120.0);
    double d[3];
    if (target) memcpy(s->target, target, sizeof s->target);
    else memcpy(s->target, f->camera.look_at, sizeof s->target);
    for (int i = 0; i < 3; i++) d[i] = s->target[i] - s->pos[i];
    const double *la = f->camera.look_at;
    if (!target && (!(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0) || (la[0] == 0 && la[1] == 0 && la[2] == 0))) {
        /* the default look-at (zero, camera.h): 1 km ahead */
        view_state_forward(s, d);
        for (int i = 0; i < 3; i++) d[i] *= 1000.0, s->target[i] = s->pos[i] + d[i];
    }
    /* a tenth of the distance to what is looked at per second, at least 5 m/s */
    s->speed = fmax(5.0, 0.1 * sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    atmos_direction_to_angles(f->sun_dir, &s->sun_el, &s->sun_az);
    s->sun_from_time = sc->sun.from_time;
    s->time = sc->sun.time;
    s->lat = sc->sun.latitude_deg, s->lon = sc->sun.longitude_deg;
    s->manual_exposure = f->tonemap.manual_exposure;
    s->ev = f->tonemap.exposure_ev;
    s->renderer = sc->renderer;
    s->has_volume = sc->volume.source[0] != 0;
    s->spectral = sc->wavelengths == ATMOS_WAVELENGTHS_SPECTRAL;
    s->overlay = 1;
    s->changes = VIEW_CHANGED_CAMERA | VIEW_CHANGED_SUN;
}

void view_state_tap(view_state *s, view_action a)
{
    view_state_apply(s, a, view_action_held(a) ? VIEW_TAP_S : 0.0, 0, 0);
}

/* Moves the camera along its own axes (or, orbiting, about the target). */
static void fly(view_state *s, double fwd, double right, double up)
{
    if (s->orbit) {
        double d[3];
        for (int i = 0; i < 3; i++) d[i] = s->pos[i] - s->target[i];
        const double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        const double nr = fmax(1.0, r - fwd);
        double el, az;
        atmos_direction_to_angles(d, &el, &az);
        /* one radian of orbit per `r` metres of flight */
        az = wrap360(az - right / fmax(r, 1e-9) / DEG);
        el = clampd(el + up / fmax(r, 1e-9) / DEG, -89.0, 89.0);
        atmos_direction_from_angles(el, az, d);
        for (int i = 0; i < 3; i++) s->pos[i] = s->target[i] + nr * d[i];
        for (int i = 0; i < 3; i++) d[i] = -d[i];
        atmos_direction_to_angles(d, &s->pitch_deg, &s->yaw_deg);
    } else {
        double f[3], rt[3];
        view_state_forward(s, f);
        atmos_direction_from_angles(0.0, wrap360(s->yaw_deg + 90.0), rt);
        for (int i = 0; i < 3; i++) s->pos[i] += fwd * f[i] + right * rt[i];
        s->pos[1] += up;
    }
    s->pos[1] = fmax(s->pos[1], 0.5); /* never below the ground */
    s->changes |= VIEW_CHANGED_CAMERA;
}

static void turn(view_state *s, double dyaw, double dpitch)
{
    s->yaw_deg = wrap360(s->yaw_deg + dyaw);
    s->pitch_deg = clampd(s->pitch_deg + dpitch, -view_state_pitch_limit(s), view_state_pitch_limit(s));
    s->changes |= VIEW_CHANGED_CAMERA;
}

static void move_sun(view_state *s, double del, double daz)
{
    s->sun_from_time = 0; /* dragged by hand: the angles rule from now on */
    s->sun_el = clampd(s->sun_el + del, -90.0, 90.0);
    s->sun_az = wrap360(s->sun_az + daz);
    s->changes |= VIEW_CHANGED_SUN;
}

/* Date and time scrubbing: minutes added to the instant (days and years roll over). */
static void add_minutes(view_state *s, double minutes)
{
    if (!s->sun_from_time) return;
    atmos_utc_time_from_seconds(atmos_utc_time_seconds(&s->time) + 60.0 * minutes, &s->time);
    view_state_sun(s);
    s->changes |= VIEW_CHANGED_SUN;
}

atmos_renderer_kind view_next_renderer(atmos_renderer_kind r, int has_volume)
{
    /* slice -> harris -> nishita -> path -> sky -> slice with a volume; sky alone without */
    const atmos_renderer_kind next = r == ATMOS_RENDERER_SLICE     ? ATMOS_RENDERER_HARRIS
                                     : r == ATMOS_RENDERER_HARRIS  ? ATMOS_RENDERER_NISHITA
                                     : r == ATMOS_RENDERER_NISHITA ? ATMOS_RENDERER_PATH
                                     : r == ATMOS_RENDERER_PATH    ? ATMOS_RENDERER_SKY
                                                                   : ATMOS_RENDERER_SLICE;
    return has_volume || next == ATMOS_RENDERER_SKY ? next : r;
}

void view_state_apply(view_state *s, view_action a, double dt, int fast, int slow)
{
    const double mult = fast ? 10.0 : (slow ? 0.1 : 1.0);
    const double step = s->speed * mult * dt, ang = 60.0 * mult * dt, sun = 20.0 * mult * dt;
    switch (a) {
    case VA_FORWARD: fly(s, step, 0, 0); break;
    case VA_BACK: fly(s, -step, 0, 0); break;
    case VA_LEFT: fly(s, 0, -step, 0); break;
    case VA_RIGHT: fly(s, 0, step, 0); break;
    case VA_UP: fly(s, 0, 0, step); break;
    case VA_DOWN: fly(s, 0, 0, -step); break;
    case VA_LOOK_LEFT: turn(s, -ang, 0); break;
    case VA_LOOK_RIGHT: turn(s, ang, 0); break;
    case VA_LOOK_UP: turn(s, 0, ang); break;
    case VA_LOOK_DOWN: turn(s, 0, -ang); break;
    case VA_SUN_UP: move_sun(s, sun, 0); break;
    case VA_SUN_DOWN: move_sun(s, -sun, 0); break;
    case VA_SUN_LEFT: move_sun(s, 0, -2 * sun); break;
    case VA_SUN_RIGHT: move_sun(s, 0, 2 * sun); break;
    case VA_TIME_BACK: add_minutes(s, -15.0 * mult); break;
    case VA_TIME_FORWARD: add_minutes(s, 15.0 * mult); break;
    case VA_ZOOM_IN: view_state_zoom(s, 1); break;
    case VA_ZOOM_OUT: view_state_zoom(s, -1); break;
    case VA_EXPOSURE_UP: s->ev += s->manual_exposure ? -0.5 : 0.5; s->changes |= VIEW_CHANGED_LOOK; break;
    case VA_EXPOSURE_DOWN: s->ev -= s->manual_exposure ? -0.5 : 0.5; s->changes |= VIEW_CHANGED_LOOK; break;
    case VA_ORBIT: s->orbit = !s->orbit; break;
    case VA_RENDERER:
        s->renderer = view_next_renderer(s->renderer, s->has_volume);
        s->changes |= VIEW_CHANGED_PLAN;
        break;
    case VA_SPECTRAL: s->spectral = !s->spectral; s->changes |= VIEW_CHANGED_PLAN; break;
    case VA_OVERLAY: s->overlay = !s->overlay; s->changes |= VIEW_CHANGED_LOOK; break;
    case VA_SAVE: s->save = 1; break;
    case VA_QUIT: s->quit = 1; break;
    default: break;
    }
}

void view_state_look(view_state *s, double dx, double dy)
{
    if (s->orbit) fly(s, 0, -dx * s->speed * 0.05, dy * s->speed * 0.05);
    else turn(s, 0.15 * dx, -0.15 * dy);
}

void view_state_zoom(view_state *s, double clicks)
{
    /* the field of view of the camera shown: the scene's, or its stand-in pinhole's */
    const atmos_camera_type t = view_state_camera(s, NULL);
    if (t == ATMOS_CAMERA_EQUIRECT) return; /* it shows every direction */
    double *fov = t == s->camera ? &s->fov_deg : &s->pinhole_fov_deg;
    *fov = clampd(*fov * pow(0.9, clicks), 5.0, t == ATMOS_CAMERA_FISHEYE ? 360.0 : 120.0);
    s->changes |= VIEW_CHANGED_CAMERA;
}

void view_state_frame(const view_state *s, atmos_frame *f)
{
    double d[3];
    view_state_forward(s, d);
    f->camera.type = view_state_camera(s, &f->camera.fov_deg);
    memcpy(f->camera.position, s->pos, sizeof s->pos);
    /* looked-at point 1 km ahead: the direction is what matters */
    for (int i = 0; i < 3; i++) f->camera.look_at[i] = s->pos[i] + 1000.0 * d[i];
    view_state_up(s, f->camera.up);
    atmos_direction_from_angles(s->sun_el, s->sun_az, f->sun_dir);
    f->tonemap.manual_exposure = s->manual_exposure;
    f->tonemap.exposure_ev = s->ev;
}
