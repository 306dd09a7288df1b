/* The viewer's window (view.h): SDL2 for the window, the events and the texture that shows
 * the CPU-rendered frame; SDL2_ttf for the overlay's text (DejaVu Sans Mono from Debian's
 * fonts-dejavu-core, or the font ATMOS_VIEW_FONT names; without a font the overlay goes to
 * the window's title). */
#include "view.h"

#include <SDL2/SDL.h>
#include <SDL2/SDL_ttf.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_FONT "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf"

struct view_window {
    SDL_Window *win;
    SDL_Renderer *ren;
    SDL_Texture *tex;
    int tw, th;
    TTF_Font *font;
    int held[VA_COUNT];
    int dragging;
};

#define NO_DISPLAY_HINT                                                                                       \
    "record headless with --headless --frames N [--record DIR], or run it under a virtual display: xvfb-run -a " \
    "atmos view ..."

/* SDL2's video drivers that open no window anyone sees: without a display, SDL_Init falls back
 * on "offscreen" (SDL 2.26) and succeeds. Kept when SDL_VIDEODRIVER asks for them. */
static int shows_nothing(const char *driver)
{
    if (!driver || (strcmp(driver, "offscreen") && strcmp(driver, "dummy"))) return 0;
    const char *asked = getenv("SDL_VIDEODRIVER");
    return !(asked && strstr(asked, driver));
}

view_window *view_window_open(int w, int h, const char *title)
{
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        fprintf(stderr, "atmos view: cannot open a window: %s (no display?): " NO_DISPLAY_HINT "\n", SDL_GetError());
        return NULL;
    }
    const char *driver = SDL_GetCurrentVideoDriver();
    if (shows_nothing(driver)) {
        const char *x = getenv("DISPLAY"), *wl = getenv("WAYLAND_DISPLAY");
        fprintf(stderr,
                "atmos view: no display to open a window on (%s; SDL2 could only fall back on its \"%s\" video "
                "driver, which shows nothing): " NO_DISPLAY_HINT "\n",
                (x && *x) || (wl && *wl) ? "the display in DISPLAY / WAYLAND_DISPLAY could not be opened"
                                         : "neither DISPLAY nor WAYLAND_DISPLAY is set",
                driver);
        SDL_Quit();
        return NULL;
    }
    view_window *v = calloc(1, sizeof *v);
    if (!v) {
        SDL_Quit();
        return NULL;
    }
    v->win = SDL_CreateWindow(title, SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, w, h, SDL_WINDOW_RESIZABLE);
    if (v->win) v->ren = SDL_CreateRenderer(v->win, -1, 0);
    if (!v->win || !v->ren) {
        fprintf(stderr, "atmos view: cannot open a window (video driver %s): %s: " NO_DISPLAY_HINT "\n",
                driver ? driver : "none", SDL_GetError());
        view_window_close(v);
        return NULL;
    }
    if (TTF_Init() == 0) {
        const char *path = getenv("ATMOS_VIEW_FONT");
        v->font = TTF_OpenFont(path && *path ? path : DEFAULT_FONT, 14);
    }
    return v;
}

void view_window_close(view_window *v)
{
    if (!v) return;
    if (v->font) TTF_CloseFont(v->font);
    if (TTF_WasInit()) TTF_Quit();
    if (v->tex) SDL_DestroyTexture(v->tex);
    if (v->ren) SDL_DestroyRenderer(v->ren);
    if (v->win) SDL_DestroyWindow(v->win);
    free(v);
    SDL_Quit();
}

/* The frame into the streaming texture (8-bit, as the display shows it). */
static int upload(view_window *v, const unsigned char *rgba, int w, int h)
{
    if (!v->tex || v->tw != w || v->th != h) {
        if (v->tex) SDL_DestroyTexture(v->tex);
        v->tex = SDL_CreateTexture(v->ren, SDL_PIXELFORMAT_ABGR8888, SDL_TEXTUREACCESS_STREAMING, w, h);
        if (!v->tex) return -1;
        v->tw = w, v->th = h;
    }
    return SDL_UpdateTexture(v->tex, NULL, rgba, 4 * w);
}

static void draw_lines(view_window *v, const char *const *lines, int n)
{
    if (!v->font) {
        char title[512] = "atmos view";
        for (int i = 0; i < n && i < 2; i++) {
            strncat(title, " | ", sizeof title - strlen(title) - 1);
            strncat(title, lines[i], sizeof title - strlen(title) - 1);
        }
        SDL_SetWindowTitle(v->win, title);
        return;
    }
    const SDL_Color fg = {255, 255, 255, 255};
    int y = 6;
    for (int i = 0; i < n; i++) {
        SDL_Surface *s = TTF_RenderUTF8_Blended(v->font, lines[i], fg);
        if (!s) continue;
        SDL_Texture *t = SDL_CreateTextureFromSurface(v->ren, s);
        if (t) {
            SDL_Rect bg = {4, y - 1, s->w + 6, s->h + 2}, r = {7, y, s->w, s->h};
            SDL_SetRenderDrawBlendMode(v->ren, SDL_BLENDMODE_BLEND);
            SDL_SetRenderDrawColor(v->ren, 0, 0, 0, 140);
            SDL_RenderFillRect(v->ren, &bg);
            SDL_RenderCopy(v->ren, t, NULL, &r);
            SDL_DestroyTexture(t);
        }
        y += s->h + 2;
        SDL_FreeSurface(s);
    }
}

int view_window_present(view_window *v, const unsigned char *rgba, int w, int h, const char *const *lines, int nlines)
{
    if (upload(v, rgba, w, h) != 0) return -1;
    SDL_RenderClear(v->ren);
    SDL_RenderCopy(v->ren, v->tex, NULL, NULL);
    if (lines && nlines > 0) draw_lines(v, lines, nlines);
    SDL_RenderPresent(v->ren);
    return 0;
}

/* A held action's press acts at once by a tap's worth (VIEW_TAP_S), then for every frame's
 * time while held. */

static void key_event(view_window *v, view_state *s, const SDL_KeyboardEvent *k)
{
    const view_action a = view_key_action(k->keysym.sym);
    if (a == VA_NONE) return;
    const int fast = (k->keysym.mod & KMOD_SHIFT) != 0, slow = (k->keysym.mod & KMOD_CTRL) != 0;
    if (view_action_held(a)) {
        if (k->type == SDL_KEYDOWN && !k->repeat) {
            v->held[a] = 1 + fast + 2 * slow;
            view_state_apply(s, a, VIEW_TAP_S, fast, slow);
        } else if (k->type == SDL_KEYUP) {
            v->held[a] = 0;
        }
    } else if (k->type == SDL_KEYDOWN) {
        view_state_apply(s, a, 0.0, fast, slow);
    }
}

void view_window_events(view_window *v, view_state *s, double dt)
{
    int pressed[VA_COUNT] = {0};
    SDL_Event e;
    while (SDL_PollEvent(&e)) {
        switch (e.type) {
        case SDL_QUIT: s->quit = 1; break;
        case SDL_KEYDOWN:
            if (!e.key.repeat) pressed[view_key_action(e.key.keysym.sym)] = 1;
            key_event(v, s, &e.key);
            break;
        case SDL_KEYUP: key_event(v, s, &e.key); break;
        case SDL_MOUSEBUTTONDOWN: v->dragging = 1; break;
        case SDL_MOUSEBUTTONUP: v->dragging = 0; break;
        case SDL_MOUSEMOTION:
            if (v->dragging) view_state_look(s, e.motion.xrel, e.motion.yrel);
            break;
        case SDL_MOUSEWHEEL: view_state_zoom(s, e.wheel.y); break;
        default: break;
        }
    }
    /* held keys act for the frame's time (not again in the frame they were pressed in) */
    for (int a = 1; a < VA_COUNT; a++)
        if (v->held[a] && !pressed[a]) {
            const int m = v->held[a] - 1;
            view_state_apply(s, (view_action)a, dt, m & 1, (m & 2) != 0);
        }
}

void view_window_push_key(view_window *v, int sym)
{
    (void)v;
    SDL_Event e;
    memset(&e, 0, sizeof e);
    e.type = SDL_KEYDOWN;
    e.key.type = SDL_KEYDOWN;
    e.key.state = SDL_PRESSED;
    e.key.keysym.sym = sym;
    SDL_PushEvent(&e);
    e.type = e.key.type = SDL_KEYUP;
    e.key.state = SDL_RELEASED;
    SDL_PushEvent(&e);
}
