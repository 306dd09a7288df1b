/* Cameras (include/atmos/camera.h): the world frame and angle convention, and the
 * geometry of each projection checked against closed forms:
 *  - pinhole: a ray at image-plane offset (u, v) makes atan(|(u, v)|) with the axis, so
 *    the top edge is at half the vertical FOV and the side edges at half of
 *    2 atan(tan(v/2) W/H) (the standard perspective relation between FOVs and aspect);
 *  - equidistant fisheye: angle from the axis = (r / R) * fov/2 (r distance from the
 *    image centre, R radius of the inscribed circle);
 *  - equirectangular: azimuth linear in x (north at the centre), elevation linear in y.
 * Frame: x east, y up, z south; azimuth clockwise from north (docs/models.md). */
#include "atmos/atmos.h"
#include "core/pinhole.h"
#include "test.h"

#include <math.h>
#include <string.h>

static const double PI = 3.14159265358979323846;
static double deg(double rad) { return rad * 180.0 / PI; }
static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double len(const double a[3]) { return sqrt(dot(a, a)); }
/* Angle between two vectors in degrees, robust near 0 (atan2 of |a x b| and a.b). */
static double angle_deg(const double a[3], const double b[3])
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return deg(atan2(len(c), dot(a, b)));
}

static void test_angles(void)
{
    double d[3];
    /* The frame convention, point by point. */
    atmos_direction_from_angles(0, 0, d); /* north at the horizon */
    CHECK_NEAR(d[0], 0, 1e-12); CHECK_NEAR(d[1], 0, 1e-12); CHECK_NEAR(d[2], -1, 1e-12);
    atmos_direction_from_angles(0, 90, d); /* east */
    CHECK_NEAR(d[0], 1, 1e-12); CHECK_NEAR(d[1], 0, 1e-12); CHECK_NEAR(d[2], 0, 1e-12);
    atmos_direction_from_angles(0, 180, d); /* south = +z */
    CHECK_NEAR(d[0], 0, 1e-12); CHECK_NEAR(d[1], 0, 1e-12); CHECK_NEAR(d[2], 1, 1e-12);
    atmos_direction_from_angles(0, 270, d); /* west */
    CHECK_NEAR(d[0], -1, 1e-12); CHECK_NEAR(d[1], 0, 1e-12); CHECK_NEAR(d[2], 0, 1e-12);
    atmos_direction_from_angles(90, 123, d); /* zenith, whatever the azimuth */
    CHECK_NEAR(d[0], 0, 1e-12); CHECK_NEAR(d[1], 1, 1e-12); CHECK_NEAR(d[2], 0, 1e-12);
    atmos_direction_from_angles(-90, 0, d);
    CHECK_NEAR(d[1], -1, 1e-12);
    /* 30 deg up towards north-east: y = sin 30, horizontal part cos 30 split equally. */
    atmos_direction_from_angles(30, 45, d);
    CHECK_NEAR(d[1], 0.5, 1e-12);
    CHECK_NEAR(d[0], cos(PI / 6) * sqrt(0.5), 1e-12);
    CHECK_NEAR(d[2], -cos(PI / 6) * sqrt(0.5), 1e-12);

    /* Round trip over a grid, including negative elevations; directions are unit. */
    int bad = 0, nonunit = 0;
    for (double el = -85; el <= 85; el += 17)
        for (double az = 0; az < 360; az += 22.5) {
            double e2, a2;
            atmos_direction_from_angles(el, az, d);
            if (fabs(len(d) - 1) > 1e-12) nonunit++;
            atmos_direction_to_angles(d, &e2, &a2);
            double da = fmod(fabs(a2 - az), 360.0);
            if (da > 180) da = 360 - da;
            if (fabs(e2 - el) > 1e-9 || da > 1e-9 || a2 < 0 || a2 >= 360) bad++;
        }
    CHECK_MSG(bad == 0, "%d round trips failed", bad);
    CHECK_MSG(nonunit == 0, "%d non-unit directions", nonunit);

    /* to_angles accepts non-unit vectors and returns azimuth in [0, 360). */
    double e, a;
    double v[3] = {-3, 0, -3}; /* north-west, level, length 3 sqrt 2 */
    atmos_direction_to_angles(v, &e, &a);
    CHECK_NEAR(e, 0, 1e-12);
    CHECK_NEAR(a, 315, 1e-9);
    double up[3] = {0, 2, 0};
    atmos_direction_to_angles(up, &e, &a);
    CHECK_NEAR(e, 90, 1e-12);
    CHECK(isfinite(a));
}

static atmos_camera make(atmos_context *ctx, const atmos_camera_desc *d, int w, int h)
{
    atmos_camera cam;
    memset(&cam, 0, sizeof cam);
    CHECK_OK(atmos_camera_init(ctx, d, w, h, &cam));
    return cam;
}

static void test_pinhole(atmos_context *ctx)
{
    /* An oblique look direction so that no axis-aligned shortcut passes by accident. */
    atmos_camera_desc d;
    memset(&d, 0, sizeof d);
    d.type = ATMOS_CAMERA_PINHOLE;
    double pos[3] = {100, 250, -40}, look[3];
    atmos_direction_from_angles(20, 230, look);
    for (int i = 0; i < 3; i++) d.position[i] = pos[i], d.look_at[i] = pos[i] + 5000 * look[i];
    d.up[1] = 1;
    d.fov_deg = 50;
    const int W = 300, H = 200;
    atmos_camera cam = make(ctx, &d, W, H);
    double r[3];

    CHECK(atmos_camera_ray(&cam, W / 2.0, H / 2.0, r) == 1);
    CHECK_NEAR(angle_deg(r, look), 0, 1e-9);
    CHECK_NEAR(len(r), 1, 1e-12);

    /* Top edge centre: half the vertical FOV, and above the axis. */
    atmos_camera_ray(&cam, W / 2.0, 0, r);
    CHECK_NEAR(angle_deg(r, look), 25, 1e-9);
    double el0, el1, az0, az1;
    atmos_direction_to_angles(look, &el0, &az0);
    atmos_direction_to_angles(r, &el1, &az1);
    CHECK_NEAR(el1, 45, 1e-9); /* up is +y: the top-centre ray lies in the vertical plane */
    CHECK_NEAR(az1, 230, 1e-9);
    atmos_camera_ray(&cam, W / 2.0, H, r);
    CHECK_NEAR(angle_deg(r, look), 25, 1e-9);
    atmos_direction_to_angles(r, &el1, &az1);
    CHECK_NEAR(el1, -5, 1e-9);

    /* Horizontal FOV from the aspect ratio. */
    double hfov = 2 * deg(atan(tan(25 * PI / 180) * W / H));
    double rl[3], rr[3];
    atmos_camera_ray(&cam, 0, H / 2.0, rl);
    atmos_camera_ray(&cam, W, H / 2.0, rr);
    CHECK_NEAR(angle_deg(rl, rr), hfov, 1e-9);
    CHECK_NEAR(angle_deg(rl, look), hfov / 2, 1e-9);
    /* The right edge is to the right (clockwise) of the look azimuth. */
    atmos_direction_to_angles(rr, &el1, &az1);
    CHECK(az1 > 230 && az1 < 230 + hfov);
    atmos_direction_to_angles(rl, &el1, &az1);
    CHECK(az1 < 230 && az1 > 230 - hfov);

    /* Straight lines: image-plane offset t gives angle atan(t * tan(v/2)) off axis. */
    for (int k = 1; k <= 4; k++) {
        double t = k / 4.0;
        atmos_camera_ray(&cam, W / 2.0, H / 2.0 * (1 - t), r);
        CHECK_NEAR(angle_deg(r, look), deg(atan(t * tan(25 * PI / 180))), 1e-9);
    }

    /* Defaults: looking north, level, 60 degrees; a level ray at the right edge points east of north. */
    atmos_camera_desc def;
    double origin[3] = {0, 2, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, origin, &def);
    CHECK_NEAR(def.fov_deg, 60, 0);
    atmos_camera c2 = make(ctx, &def, 64, 64);
    atmos_camera_ray(&c2, 32, 32, r);
    CHECK_NEAR(r[2], -1, 1e-12);
    atmos_camera_ray(&c2, 32, 0, r);
    CHECK_NEAR(deg(asin(r[1])), 30, 1e-9);
    atmos_camera_ray(&c2, 64, 32, r);
    CHECK(r[0] > 0);

    /* Zero fov in a desc means the default (header: "zero means default"). */
    def.fov_deg = 0;
    c2 = make(ctx, &def, 64, 64);
    atmos_camera_ray(&c2, 32, 0, r);
    CHECK_NEAR(deg(asin(r[1])), 30, 1e-9);
}

static void test_fisheye(atmos_context *ctx)
{
    /* A fisheye looking at the horizon towards the east, 200 degree field. */
    atmos_camera_desc d;
    memset(&d, 0, sizeof d);
    d.type = ATMOS_CAMERA_FISHEYE;
    double axis[3];
    atmos_direction_from_angles(0, 90, axis);
    d.position[1] = 10;
    for (int i = 0; i < 3; i++) d.look_at[i] = d.position[i] + axis[i];
    d.up[1] = 1;
    d.fov_deg = 200;
    const int W = 400, H = 300; /* inscribed circle of radius 150 px */
    const double R = 150, cx = 200, cy = 150;
    atmos_camera cam = make(ctx, &d, W, H);
    double r[3];
    CHECK(atmos_camera_ray(&cam, cx, cy, r) == 1);
    CHECK_NEAR(angle_deg(r, axis), 0, 1e-9);

    /* Equidistant: angle linear in radius, in several directions. */
    const double dirs[4][2] = {{1, 0}, {0, -1}, {-0.6, 0.8}, {0.28, 0.96}};
    int bad = 0;
    for (int k = 0; k < 4; k++)
        for (int j = 1; j <= 10; j++) {
            double rad = R * j / 10.0;
            int ok = atmos_camera_ray(&cam, cx + dirs[k][0] * rad, cy + dirs[k][1] * rad, r);
            double want = 100.0 * j / 10.0;
            if (!ok || fabs(angle_deg(r, axis) - want) > 1e-7 || fabs(len(r) - 1) > 1e-12) {
                bad++;
                fprintf(stderr, "fisheye dir %d r=%g: ok %d angle %.9f want %.9f\n", k, rad, ok, angle_deg(r, axis), want);
            }
        }
    CHECK_MSG(bad == 0, "%d fisheye radii off the equidistant law", bad);
    /* The edge of the circle is at fov/2 (here beyond 90 degrees: looking backwards). */
    CHECK(atmos_camera_ray(&cam, cx, cy - R, r) == 1);
    CHECK_NEAR(angle_deg(r, axis), 100, 1e-9);
    /* Image up is world up: the top of the circle is 100 degrees up from east, i.e.
     * tilted 10 degrees past the zenith towards the west. */
    double el, az;
    atmos_direction_to_angles(r, &el, &az);
    CHECK_NEAR(el, 80, 1e-7);
    CHECK_NEAR(az, 270, 1e-7);

    /* Outside the inscribed circle: no ray. */
    CHECK(atmos_camera_ray(&cam, 0, 0, r) == 0);
    CHECK(atmos_camera_ray(&cam, W, H, r) == 0);
    CHECK(atmos_camera_ray(&cam, cx + R * 1.001, cy, r) == 0);
    CHECK(atmos_camera_ray(&cam, cx + R * 0.75, cy - R * 0.75, r) == 0); /* 1.06 R on the diagonal */
    CHECK(atmos_camera_ray(&cam, cx + R * 0.7, cy - R * 0.7, r) == 1);   /* 0.99 R */

    /* Default fisheye: zenith at the centre, north at the top, east on the LEFT (a
     * sky chart, seen from below), 180 degrees: the circle's edge is the horizon. */
    atmos_camera_desc def;
    double origin[3] = {0, 0, 0};
    atmos_camera_defaults(ATMOS_CAMERA_FISHEYE, origin, &def);
    CHECK_NEAR(def.fov_deg, 180, 0);
    atmos_camera sky = make(ctx, &def, 100, 100);
    atmos_camera_ray(&sky, 50, 50, r);
    CHECK_NEAR(r[1], 1, 1e-12);
    atmos_camera_ray(&sky, 50, 0, r); /* top: north horizon */
    atmos_direction_to_angles(r, &el, &az);
    CHECK_NEAR(el, 0, 1e-9);
    CHECK_NEAR(r[2], -1, 1e-9);
    atmos_camera_ray(&sky, 0, 50, r); /* left: east */
    CHECK_NEAR(r[0], 1, 1e-9);
    atmos_camera_ray(&sky, 100, 50, r); /* right: west */
    CHECK_NEAR(r[0], -1, 1e-9);
    atmos_camera_ray(&sky, 50, 100, r); /* bottom: south */
    CHECK_NEAR(r[2], 1, 1e-9);
    atmos_camera_ray(&sky, 50, 25, r); /* half way up: 45 degrees elevation towards north */
    atmos_direction_to_angles(r, &el, &az);
    CHECK_NEAR(el, 45, 1e-9);
    CHECK_NEAR(az, 0, 1e-9);
    /* A zero-initialised fisheye desc means the same thing. */
    atmos_camera_desc zero;
    memset(&zero, 0, sizeof zero);
    zero.type = ATMOS_CAMERA_FISHEYE;
    atmos_camera z = make(ctx, &zero, 100, 100);
    atmos_camera_ray(&z, 0, 50, r);
    CHECK_NEAR(r[0], 1, 1e-9);
    atmos_camera_ray(&z, 50, 0, r);
    CHECK_NEAR(r[2], -1, 1e-9);
}

static void test_equirect(atmos_context *ctx)
{
    atmos_camera_desc d;
    double origin[3] = {0, 50, 0};
    atmos_camera_defaults(ATMOS_CAMERA_EQUIRECT, origin, &d);
    const int W = 360, H = 180;
    atmos_camera cam = make(ctx, &d, W, H);
    double r[3], el, az;
    CHECK(atmos_camera_ray(&cam, W / 2.0, H / 2.0, r) == 1); /* north at the horizon */
    CHECK_NEAR(r[0], 0, 1e-12); CHECK_NEAR(r[1], 0, 1e-12); CHECK_NEAR(r[2], -1, 1e-12);
    atmos_camera_ray(&cam, 3 * W / 4.0, H / 2.0, r); /* east */
    CHECK_NEAR(r[0], 1, 1e-12); CHECK_NEAR(r[1], 0, 1e-12); CHECK_NEAR(r[2], 0, 1e-12);
    atmos_camera_ray(&cam, W / 4.0, H / 2.0, r); /* west */
    CHECK_NEAR(r[0], -1, 1e-12);
    atmos_camera_ray(&cam, 0.5, H / 2.0, r); /* left edge: south */
    CHECK(r[2] > 0.9999);
    /* Azimuth grows to the right, one degree per pixel here; elevation one degree per row. */
    int bad = 0, nonunit = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            atmos_camera_ray(&cam, i + 0.5, j + 0.5, r);
            if (fabs(len(r) - 1) > 1e-12) nonunit++;
            atmos_direction_to_angles(r, &el, &az);
            double want_az = fmod(i + 0.5 - 180 + 360, 360), want_el = 90 - (j + 0.5);
            double da = fabs(az - want_az);
            if (da > 180) da = 360 - da;
            if (fabs(el - want_el) > 1e-9 || da > 1e-7) bad++;
        }
    CHECK_MSG(nonunit == 0, "%d non-unit equirect rays", nonunit);
    CHECK_MSG(bad == 0, "%d equirect pixels off the lat-long map", bad);
    atmos_camera_ray(&cam, W / 2.0, 0.5, r); /* top row: within half a degree of the zenith */
    atmos_direction_to_angles(r, &el, &az);
    CHECK_NEAR(el, 89.5, 1e-9);
    atmos_camera_ray(&cam, W / 2.0, H - 0.5, r);
    atmos_direction_to_angles(r, &el, &az);
    CHECK_NEAR(el, -89.5, 1e-9);
}

/* Expects ATMOS_E_INVALID_ARG and an error message containing `field`. */
static void expect_invalid(atmos_context *ctx, const atmos_camera_desc *d, int w, int h, const char *field,
                           const char *what)
{
    atmos_camera cam;
    atmos_context_clear_error(ctx);
    atmos_status st = atmos_camera_init(ctx, d, w, h, &cam);
    CHECK_MSG(st == ATMOS_E_INVALID_ARG, "%s: status %s", what, atmos_status_string(st));
    const char *msg = atmos_context_error(ctx);
    CHECK_MSG(msg && strstr(msg, field), "%s: message '%s' does not name '%s'", what, msg ? msg : "(null)", field);
}

static void test_invalid(atmos_context *ctx)
{
    atmos_camera_desc d, base;
    double pos[3] = {0, 100, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &base);

    d = base; d.fov_deg = 180; expect_invalid(ctx, &d, 64, 64, "fov_deg", "pinhole fov 180");
    d = base; d.fov_deg = -10; expect_invalid(ctx, &d, 64, 64, "fov_deg", "pinhole fov -10");
    d = base; d.fov_deg = 270; expect_invalid(ctx, &d, 64, 64, "fov_deg", "pinhole fov 270");
    d = base; d.fov_deg = NAN; expect_invalid(ctx, &d, 64, 64, "fov_deg", "pinhole fov NaN");
    d = base; d.fov_deg = INFINITY; expect_invalid(ctx, &d, 64, 64, "fov_deg", "pinhole fov inf");
    d = base; d.type = ATMOS_CAMERA_FISHEYE; d.fov_deg = 360.5; expect_invalid(ctx, &d, 64, 64, "fov_deg", "fisheye fov 360.5");
    d = base; d.type = ATMOS_CAMERA_FISHEYE; d.fov_deg = -1; expect_invalid(ctx, &d, 64, 64, "fov_deg", "fisheye fov -1");
    d = base; for (int i = 0; i < 3; i++) d.look_at[i] = d.position[i];
    expect_invalid(ctx, &d, 64, 64, "look_at", "look_at == position");
    d = base; d.up[0] = 0, d.up[1] = 0, d.up[2] = -3; /* parallel to the view (north) */
    expect_invalid(ctx, &d, 64, 64, "up", "up parallel to view");
    d = base; d.up[2] = 2; /* anti-parallel */
    d.up[1] = 0;
    expect_invalid(ctx, &d, 64, 64, "up", "up anti-parallel to view");
    d = base; d.position[1] = -1; d.look_at[1] = -1;
    expect_invalid(ctx, &d, 64, 64, "position", "negative altitude");
    d = base; d.position[0] = NAN; expect_invalid(ctx, &d, 64, 64, "position", "NaN position");
    d = base; d.look_at[2] = NAN; expect_invalid(ctx, &d, 64, 64, "look_at", "NaN look_at");
    d = base; d.up[1] = NAN; expect_invalid(ctx, &d, 64, 64, "up", "NaN up");
    d = base; d.type = (atmos_camera_type)7; expect_invalid(ctx, &d, 64, 64, "type", "unknown type");
    d = base; expect_invalid(ctx, &d, 0, 64, "size", "zero width");
    /* A fisheye at the full 360 degrees is valid. */
    atmos_camera cam;
    d = base; d.type = ATMOS_CAMERA_FISHEYE; d.fov_deg = 360;
    CHECK_OK(atmos_camera_init(ctx, &d, 64, 64, &cam));
    CHECK_OK(atmos_camera_init(ctx, &base, 64, 64, &cam));
}

/* A pinhole camera's rays a row at a time (atmos__camera_pinhole_dirs, the beams' subsampled
 * frames) are atmos_camera_ray's to the bit, over an odd width (the vector loop's tail) and an
 * oblique view. */
static void test_pinhole_rows(atmos_context *ctx)
{
    atmos_camera_desc d;
    memset(&d, 0, sizeof d);
    d.type = ATMOS_CAMERA_PINHOLE;
    const double pos[3] = {3, 7, 1.5}, look[3] = {-2, 5, -9};
    memcpy(d.position, pos, sizeof pos), memcpy(d.look_at, look, sizeof look);
    d.fov_deg = 57;
    enum { W = 37, H = 23 };
    atmos_camera cam = make(ctx, &d, W, H);
    double u[W], dx[W], dy[W], dz[W];
    for (int x = 0; x < W; x++) u[x] = atmos__camera_pinhole_u(&cam, x + 0.5);
    int differ = 0;
    for (int y = 0; y < H; y++) {
        atmos__camera_pinhole_dirs(&cam, u, W, atmos__camera_pinhole_v(&cam, y + 0.5), dx, dy, dz);
        for (int x = 0; x < W; x++) {
            double r[3];
            atmos_camera_ray(&cam, x + 0.5, y + 0.5, r);
            const double got[3] = {dx[x], dy[x], dz[x]};
            differ += memcmp(got, r, sizeof r) != 0;
        }
    }
    CHECK_MSG(differ == 0, "pinhole rows: %d of %d rays differ from atmos_camera_ray", differ, W * H);
}

int main(void)
{
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_angles();
    test_pinhole(ctx);
    test_pinhole_rows(ctx);
    test_fisheye(ctx);
    test_equirect(ctx);
    test_invalid(ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_camera");
}
