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

void view_state_sun(view_state *s)
{
    if (!s->sun_from_time) return;
    atmos_sun_position p;
    if (atmos_sun_position_compute(NULL, &s->time, s->lat, s->lon, 1, &p) == ATMOS_OK) {
        s->sun_el = p.elevation_deg;
        s->sun_az = p.azimuth_deg;
    }
}

void view_state_init(view_state *s, const atmos_scene *sc, const atmos_frame *f, const double *target)
{
    memset(s, 0, sizeof *s);
    memcpy(s->pos, f->camera.position, sizeof s->pos);
    double d[3];
    for (int i = 0; i < 3; i++) d[i] = f->camera.look_at[i] - f->camera.position[i];
    atmos_direction_to_angles(d, &s->pitch_deg, &s->yaw_deg);
    s->pitch_deg = clampd(s->pitch_deg, -89.0, 89.0);
    s->fov_deg = f->camera.fov_deg > 0 ? f->camera.fov_deg : 60.0;
    if (target) memcpy(s->target, target, sizeof s->target);
    else memcpy(s->target, f->camera.look_at, sizeof s->target);
    for (int i = 0; i < 3; i++) d[i] = s->target[i] - s->pos[i];
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
    s->pitch_deg = clampd(s->pitch_deg + dpitch, -89.0, 89.0);
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
    case VA_RENDERER: {
        /* slice -> harris -> nishita -> path -> sky -> slice with a volume; sky alone without */
        const atmos_renderer_kind next = s->renderer == ATMOS_RENDERER_SLICE     ? ATMOS_RENDERER_HARRIS
                                         : s->renderer == ATMOS_RENDERER_HARRIS  ? ATMOS_RENDERER_NISHITA
                                         : s->renderer == ATMOS_RENDERER_NISHITA ? ATMOS_RENDERER_PATH
                                         : s->renderer == ATMOS_RENDERER_PATH   ? ATMOS_RENDERER_SKY
                                                                                : ATMOS_RENDERER_SLICE;
        if (s->has_volume || next == ATMOS_RENDERER_SKY) s->renderer = s->has_volume ? next : ATMOS_RENDERER_SKY;
        s->changes |= VIEW_CHANGED_PLAN;
        break;
    }
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
    s->fov_deg = clampd(s->fov_deg * pow(0.9, clicks), 5.0, 120.0);
    s->changes |= VIEW_CHANGED_CAMERA;
}

void view_state_frame(const view_state *s, atmos_frame *f)
{
    double d[3];
    view_state_forward(s, d);
    f->camera.type = ATMOS_CAMERA_PINHOLE;
    memcpy(f->camera.position, s->pos, sizeof s->pos);
    /* looked-at point 1 km ahead: the direction is what matters */
    for (int i = 0; i < 3; i++) f->camera.look_at[i] = s->pos[i] + 1000.0 * d[i];
    f->camera.up[0] = 0, f->camera.up[1] = 1, f->camera.up[2] = 0;
    f->camera.fov_deg = s->fov_deg;
    atmos_direction_from_angles(s->sun_el, s->sun_az, f->sun_dir);
    f->tonemap.manual_exposure = s->manual_exposure;
    f->tonemap.exposure_ev = s->ev;
}
