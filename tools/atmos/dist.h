/* Distributed rendering for atmos render --mpi (docs/cluster.md): the ranks of an MPI job
 * share the work of one render, rank 0 writes every output, and the bytes are those of a
 * single process for any number of ranks. An animation's frames go round the ranks (frame i
 * to rank (i - 1) mod N); a single image is cut into bands of rows, band b rendered by rank
 * b mod N as a region of the frame (atmos_region: the values the whole frame would give).
 * Built with MPI when CMake finds it (tools/dist/dist_mpi.c), else without
 * (tools/dist/dist_serial.c: --mpi is then a usage error naming the package). */
#ifndef ATMOS_CLI_DIST_H
#define ATMOS_CLI_DIST_H

#include <atmos/atmos.h>

/* Rows in one band of a single image at most: the bands are made equal (cli_dist_band_rows)
 * and their count a multiple of the ranks', so every rank gets as many rows. */
#define CLI_DIST_BAND_ROWS 16

typedef struct cli_dist {
    int rank, size; /* 0 and 1 when not distributed */
    int active;     /* MPI was started */
} cli_dist;

/* The rows of one band of an image `height` rows high shared by `ranks`: at most
 * CLI_DIST_BAND_ROWS, as many bands as a multiple of the ranks, all of one height (the last
 * shorter by what the division leaves). 180 rows, 2 ranks: 12 bands of 15, 90 rows each
 * (bands of 16 gave 96 and 84). */
static inline int cli_dist_band_rows(int height, int ranks)
{
    const int per = ranks * CLI_DIST_BAND_ROWS, bands = ranks * ((height + per - 1) / per);
    const int rows = (height + bands - 1) / bands;
    return rows > 0 ? rows : 1;
}

/* Starts MPI when want is nonzero; fills *d. CLI_EXIT_OK, or CLI_EXIT_USAGE (message
 * printed) when this build has no MPI. */
int cli_dist_start(int want, cli_dist *d);
/* Ends MPI (every rank, after its last message). */
void cli_dist_stop(const cli_dist *d);
/* Ends every rank of the job with exit status rc; returns only when not distributed. */
void cli_dist_abort(const cli_dist *d, int rc);
/* The largest of v over all ranks (every rank calls it). */
int cli_dist_max(const cli_dist *d, int v);
/* The rank that renders frame (1-based) of an animation. */
int cli_dist_frame_owner(const cli_dist *d, int frame);
/* One image by all ranks (every rank calls it): each renders its bands of rows into img,
 * and rank 0 receives the others'. Returns the worst status over the ranks (the same on
 * every rank); info as rank 0's render reports it. */
atmos_status cli_dist_render(const cli_dist *d, atmos_plan *plan, const atmos_frame *f, atmos_image *img,
                             atmos_render_info *info);
/* A frame rendered by this rank (st its status) sent to rank 0, which receives it with
 * cli_dist_recv from that rank into an image of the same size. The receiver gets the
 * sender's status. */
atmos_status cli_dist_send(const cli_dist *d, const atmos_image *img, atmos_status st, const atmos_render_info *info);
atmos_status cli_dist_recv(const cli_dist *d, int from, atmos_image *img, atmos_render_info *info);

#endif
