/* The viewer's keys: one table makes the key handling, the --help text and the names a
 * flight script presses (view.h). SDL's key codes; no SDL calls here. */
#include "view.h"

#include <SDL2/SDL_keycode.h>
#include <string.h>
#include <strings.h>

static const view_key keys[] = {
    {SDLK_w, VA_FORWARD, "W", "fly forward (Shift: x10 faster, Ctrl: x0.1)"},
    {SDLK_s, VA_BACK, "S", "fly back"},
    {SDLK_a, VA_LEFT, "A", "fly left"},
    {SDLK_d, VA_RIGHT, "D", "fly right"},
    {SDLK_e, VA_UP, "E", "climb"},
    {SDLK_q, VA_DOWN, "Q", "descend"},
    {SDLK_LEFT, VA_LOOK_LEFT, "Left", "turn left (orbiting: the same keys as flying move about the volume)"},
    {SDLK_RIGHT, VA_LOOK_RIGHT, "Right", "turn right"},
    {SDLK_UP, VA_LOOK_UP, "Up", "look up"},
    {SDLK_DOWN, VA_LOOK_DOWN, "Down", "look down"},
    {SDLK_i, VA_SUN_UP, "I", "sun higher (20 degrees a second)"},
    {SDLK_k, VA_SUN_DOWN, "K", "sun lower"},
    {SDLK_j, VA_SUN_LEFT, "J", "sun's azimuth anticlockwise (40 degrees a second)"},
    {SDLK_l, VA_SUN_RIGHT, "L", "sun's azimuth clockwise"},
    {SDLK_LEFTBRACKET, VA_TIME_BACK, "[", "15 minutes earlier (Shift: 150; scenes with a time and place: NOAA sun)"},
    {SDLK_RIGHTBRACKET, VA_TIME_FORWARD, "]", "15 minutes later"},
    {SDLK_z, VA_ZOOM_IN, "Z", "zoom in (narrower field of view; also the mouse wheel)"},
    {SDLK_x, VA_ZOOM_OUT, "X", "zoom out"},
    {SDLK_EQUALS, VA_EXPOSURE_UP, "=", "brighter by half a stop"},
    {SDLK_KP_PLUS, VA_EXPOSURE_UP, "Keypad +", "brighter"},
    {SDLK_MINUS, VA_EXPOSURE_DOWN, "-", "darker by half a stop"},
    {SDLK_KP_MINUS, VA_EXPOSURE_DOWN, "Keypad -", "darker"},
    {SDLK_o, VA_ORBIT, "O", "orbit the volume / fly freely"},
    {SDLK_r, VA_RENDERER, "R", "next renderer: slice, harris (particles), nishita, path (progressive), sky"},
    {SDLK_v, VA_SPECTRAL, "V", "rgb / spectral wavelengths"},
    {SDLK_h, VA_OVERLAY, "H", "overlay on / off"},
    {SDLK_F12, VA_SAVE, "F12", "save the frame: EXR, PNG and the scene JSON that renders it"},
    {SDLK_p, VA_SAVE, "P", "the same"},
    {SDLK_ESCAPE, VA_QUIT, "Esc", "quit"},
    {0, VA_NONE, NULL, NULL},
};

/* Script names of the actions, in view_action's order. */
static const char *const names[VA_COUNT] = {
    "none",     "forward",       "back",         "left",      "right",        "up",       "down",
    "look_left", "look_right",   "look_up",      "look_down", "sun_up",       "sun_down", "sun_left",
    "sun_right", "time_back",    "time_forward", "zoom_in",   "zoom_out",     "brighter", "darker",
    "orbit",    "renderer",      "spectral",     "overlay",   "save",         "quit",
};

const view_key *view_keys(void) { return keys; }

view_action view_key_action(int sym)
{
    for (const view_key *k = keys; k->sym; k++)
        if (k->sym == sym) return k->action;
    return VA_NONE;
}

int view_action_held(view_action a) { return a >= VA_FORWARD && a <= VA_SUN_RIGHT; }

view_action view_action_named(const char *name)
{
    for (int i = 1; i < VA_COUNT; i++)
        if (!strcmp(names[i], name)) return (view_action)i;
    return VA_NONE;
}

const char *view_action_name(view_action a) { return a > VA_NONE && a < VA_COUNT ? names[a] : "none"; }

void view_keys_help(FILE *f)
{
    fprintf(f, "Keys (held keys act while held, a tap for 1/30 s; Shift: x10, Ctrl: x0.1):\n");
    for (const view_key *k = keys; k->sym; k++) fprintf(f, "  %-9s %s\n", k->key, k->what);
    fprintf(f, "Mouse: drag with any button to look around (orbiting: to move about the volume);\n"
               "  the wheel zooms.\n"
               "Script names of the keys (\"press\" in a flight file):");
    int col = 100; /* the names from the next line on, wrapped at 100 characters */
    for (int i = 1; i < VA_COUNT; i++) {
        if (col + (int)strlen(names[i]) + 3 > 100) fprintf(f, "%s\n ", i == 1 ? "" : ","), col = 1;
        else if (i > 1) fprintf(f, ","), col++;
        col += fprintf(f, " %s", names[i]);
    }
    fprintf(f, "\n  A flight presses all but the camera's (forward .. look_down, orbit: its key frames place the\n"
               "  camera) and, when its key frames set \"sun\", the sun's and the time's; the time's need a\n"
               "  scene whose sun follows a date, a time and a place.\n");
}

int view_key_codes(const char *list, int *codes, int cap)
{
    int n = 0;
    for (const char *p = list; *p;) {
        const char *e = strchr(p, ',');
        const size_t len = e ? (size_t)(e - p) : strlen(p);
        const view_key *k = keys;
        while (k->sym && !(strlen(k->key) == len && !strncasecmp(k->key, p, len))) k++;
        if (!k->sym) { /* a script name: its action's first key */
            char name[32] = "";
            if (len < sizeof name) memcpy(name, p, len), name[len] = 0;
            const view_action a = view_action_named(name);
            k = keys;
            while (k->sym && (a == VA_NONE || k->action != a)) k++;
        }
        if (!k->sym || n >= cap) return -1;
        codes[n++] = k->sym;
        p += len + (e != NULL);
    }
    return n;
}
