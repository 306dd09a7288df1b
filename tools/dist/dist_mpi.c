/* cli_dist over MPI (Open MPI from Debian): frames and bands of rows between the ranks of
 * MPI_COMM_WORLD, every image gathered at rank 0. Messages carry the sender's status, so a
 * rank that fails tells rank 0, which reports it and ends the job (cmd_render.c). */
#include "dist.h"
#include "cli.h"

#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { TAG_HEAD = 1, TAG_DATA = 2 };
/* Floats per message: MPI counts are ints. */
#define CHUNK ((size_t)1 << 28)

int cli_dist_start(int want, cli_dist *d)
{
    d->rank = 0, d->size = 1, d->active = 0;
    if (!want) return CLI_EXIT_OK;
    int provided = 0;
    if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
        return cli_usage_error("render", "--mpi: MPI could not be started");
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    d->active = 1;
    return CLI_EXIT_OK;
}

/* Frames a rank has sent to rank 0 without waiting for it (cli_dist_send): a copy of each
 * frame's header, metadata and pixels in flight, at most PENDING_MAX at a time, so the rank
 * renders its next frame while rank 0 is still busy with earlier ones. */
#define PENDING_MAX 3
typedef struct {
    MPI_Request req[3];
    double head[5];
    char *meta;
    float *px;
} pending_frame;
static pending_frame pending[PENDING_MAX];
static int npending;

static void pending_free(pending_frame *p)
{
    free(p->meta);
    free(p->px);
    memset(p, 0, sizeof *p);
}

/* Waits for the oldest frames until at most keep are in flight (keep 0: all). */
static void pending_wait(int keep)
{
    while (npending > keep) {
        MPI_Waitall(3, pending[0].req, MPI_STATUSES_IGNORE);
        pending_free(&pending[0]);
        memmove(pending, pending + 1, (size_t)(npending - 1) * sizeof pending[0]);
        memset(&pending[--npending], 0, sizeof pending[0]);
    }
}

void cli_dist_stop(const cli_dist *d)
{
    if (!d->active) return;
    pending_wait(0);
    MPI_Finalize();
}

void cli_dist_abort(const cli_dist *d, int rc)
{
    if (d->active && d->size > 1) MPI_Abort(MPI_COMM_WORLD, rc ? rc : 1);
}

int cli_dist_max(const cli_dist *d, int v)
{
    int out = v;
    if (d->active) MPI_Allreduce(&v, &out, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return out;
}

int cli_dist_frame_owner(const cli_dist *d, int frame)
{
    return (frame - 1) % d->size;
}

/* n floats to or from a rank, in messages of at most CHUNK. */
static void send_floats(const float *p, size_t n, int to)
{
    for (size_t i = 0; i < n; i += CHUNK)
        MPI_Send(p + i, (int)(n - i < CHUNK ? n - i : CHUNK), MPI_FLOAT, to, TAG_DATA, MPI_COMM_WORLD);
}

static void recv_floats(float *p, size_t n, int from)
{
    for (size_t i = 0; i < n; i += CHUNK)
        MPI_Recv(p + i, (int)(n - i < CHUNK ? n - i : CHUNK), MPI_FLOAT, from, TAG_DATA, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

/* The rows of rank r's bands, in order, copied between the image and a packed buffer
 * (to_img: buffer -> image). Returns the floats copied. */
static size_t copy_bands(atmos_image *img, float *buf, int r, int size, int to_img)
{
    const size_t row = (size_t)img->width * img->channels;
    const int h = cli_dist_band_rows(img->height, size);
    size_t q = 0;
    for (int y0 = r * h; y0 < img->height; y0 += size * h) {
        const int y1 = y0 + h < img->height ? y0 + h : img->height;
        float *px = img->pixels + (size_t)y0 * row;
        const size_t n = (size_t)(y1 - y0) * row;
        if (buf) memcpy(to_img ? px : buf + q, to_img ? buf + q : px, n * sizeof(float));
        q += n;
    }
    return q;
}

/* This rank's bands rendered as regions of the frame. */
static atmos_status render_bands(const cli_dist *d, atmos_plan *plan, const atmos_frame *f, atmos_image *img,
                                 atmos_render_info *info)
{
    atmos_status st = ATMOS_OK;
    double seconds = 0;
    const int h = cli_dist_band_rows(img->height, d->size);
    for (int y0 = d->rank * h; y0 < img->height && st == ATMOS_OK; y0 += d->size * h) {
        atmos_region rg = {0, y0, img->width, y0 + h < img->height ? y0 + h : img->height};
        st = atmos_plan_render(plan, f, &rg, img, info);
        seconds += info->seconds;
    }
    info->seconds = seconds;
    return st;
}

atmos_status cli_dist_render(const cli_dist *d, atmos_plan *plan, const atmos_frame *f, atmos_image *img,
                             atmos_render_info *info)
{
    if (!d->active || d->size == 1) return atmos_plan_render(plan, f, NULL, img, info);
    memset(info, 0, sizeof *info);
    atmos_status st = render_bands(d, plan, f, img, info);
    st = (atmos_status)cli_dist_max(d, (int)st);
    if (st != ATMOS_OK) return st;
    if (d->rank != 0) {
        const size_t n = copy_bands(img, NULL, d->rank, d->size, 0);
        float *buf = malloc(n * sizeof(float) + 1);
        int ok = buf != NULL;
        MPI_Send(&ok, 1, MPI_INT, 0, TAG_HEAD, MPI_COMM_WORLD);
        if (ok) copy_bands(img, buf, d->rank, d->size, 0), send_floats(buf, n, 0);
        free(buf);
        return ok ? ATMOS_OK : ATMOS_E_NOMEM;
    }
    char ranks[32];
    snprintf(ranks, sizeof ranks, "%d", d->size);
    atmos_image_set_meta(img, "atmos:ranks", ranks);
    /* Statistics of the samples are per rank: rank 0's alone would mislead. */
    if (atmos_image_get_meta(img, "atmos:path_mean_rel_error"))
        atmos_image_set_meta(img, "atmos:path_mean_rel_error", "not combined over the ranks");
    atmos_status worst = ATMOS_OK;
    for (int r = 1; r < d->size; r++) {
        int ok = 0;
        MPI_Recv(&ok, 1, MPI_INT, r, TAG_HEAD, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (!ok) { worst = ATMOS_E_NOMEM; continue; }
        const size_t n = copy_bands(img, NULL, r, d->size, 1);
        float *buf = malloc(n * sizeof(float) + 1);
        if (!buf) return ATMOS_E_NOMEM; /* the sender blocks: the caller ends the job */
        recv_floats(buf, n, r);
        copy_bands(img, buf, r, d->size, 1);
        free(buf);
    }
    return worst;
}

/* The image's metadata as "key\0value\0..." (a new buffer, *n bytes; NULL when out of memory). */
static char *pack_meta(const atmos_image *img, int *n)
{
    size_t len = 0;
    for (int i = 0; i < img->meta_count; i++) len += strlen(img->meta[i].key) + strlen(img->meta[i].value) + 2;
    char *buf = malloc(len + 1), *q = buf;
    if (!buf || len > (size_t)1 << 30) return free(buf), *n = 0, NULL;
    for (int i = 0; i < img->meta_count; i++) {
        const size_t k = strlen(img->meta[i].key) + 1, v = strlen(img->meta[i].value) + 1;
        memcpy(q, img->meta[i].key, k), q += k;
        memcpy(q, img->meta[i].value, v), q += v;
    }
    *n = (int)len;
    return buf;
}

atmos_status cli_dist_send(const cli_dist *d, const atmos_image *img, atmos_status st, const atmos_render_info *info)
{
    (void)d;
    pending_wait(PENDING_MAX - 1);
    pending_frame *p = &pending[npending];
    const size_t n = (size_t)img->width * img->height * img->channels;
    int nmeta = 0;
    if (st == ATMOS_OK) {
        p->meta = pack_meta(img, &nmeta);
        p->px = n <= CHUNK ? malloc(n * sizeof(float) + 1) : NULL;
        if (!p->meta || (n <= CHUNK && !p->px)) st = ATMOS_E_NOMEM;
        else if (p->px) memcpy(p->px, img->pixels, n * sizeof(float));
    }
    const double head[5] = {(double)st, info ? info->seconds : 0, info ? info->sun_elevation_deg : 0,
                            info ? info->sun_azimuth_deg : 0, (double)nmeta};
    memcpy(p->head, head, sizeof head);
    for (int i = 0; i < 3; i++) p->req[i] = MPI_REQUEST_NULL;
    MPI_Isend(p->head, 5, MPI_DOUBLE, 0, TAG_HEAD, MPI_COMM_WORLD, &p->req[0]);
    if (st == ATMOS_OK) {
        /* Messages between two ranks with one tag arrive in the order sent, so rank 0's
         * receives match these frames one after another. */
        MPI_Isend(p->meta, nmeta, MPI_CHAR, 0, TAG_HEAD, MPI_COMM_WORLD, &p->req[1]);
        if (p->px) MPI_Isend(p->px, (int)n, MPI_FLOAT, 0, TAG_DATA, MPI_COMM_WORLD, &p->req[2]);
    }
    npending++;
    if (st == ATMOS_OK && !p->px) { /* a frame of over 2^28 floats: sent from the image, in pieces */
        pending_wait(0);
        send_floats(img->pixels, n, 0);
    }
    if (st != ATMOS_OK) pending_wait(0);
    return st;
}

/* The frame's image with its renderer's metadata (the sun of that frame, its statistics). */
atmos_status cli_dist_recv(const cli_dist *d, int from, atmos_image *img, atmos_render_info *info)
{
    double head[5];
    MPI_Recv(head, 5, MPI_DOUBLE, from, TAG_HEAD, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    atmos_status st = (atmos_status)head[0];
    info->seconds = head[1], info->sun_elevation_deg = head[2], info->sun_azimuth_deg = head[3];
    if (st != ATMOS_OK) return st;
    const int nmeta = (int)head[4];
    char *meta = malloc((size_t)nmeta + 1);
    if (!meta) return ATMOS_E_NOMEM; /* the sender blocks: the caller ends the job */
    MPI_Recv(meta, nmeta, MPI_CHAR, from, TAG_HEAD, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    for (int q = 0; q < nmeta;) {
        const char *k = meta + q, *v = k + strlen(k) + 1;
        atmos_image_set_meta(img, k, v);
        q = (int)(v + strlen(v) + 1 - meta);
    }
    free(meta);
    recv_floats(img->pixels, (size_t)img->width * img->height * img->channels, from);
    (void)d;
    return st;
}
