/* cli_dist without MPI (this build found none): one process does all the work. */
#include "dist.h"
#include "cli.h"

int cli_dist_start(int want, cli_dist *d)
{
    d->rank = 0, d->size = 1, d->active = 0;
    if (want)
        return cli_usage_error("render", "--mpi: this atmos was built without MPI (install libopenmpi-dev and "
                                         "openmpi-bin, or run scripts/install-deps.sh, then rebuild)");
    return CLI_EXIT_OK;
}

void cli_dist_stop(const cli_dist *d) { (void)d; }

void cli_dist_abort(const cli_dist *d, int rc) { (void)d, (void)rc; }

int cli_dist_max(const cli_dist *d, int v) { return (void)d, v; }

int cli_dist_frame_owner(const cli_dist *d, int frame) { return (void)d, (void)frame, 0; }

atmos_status cli_dist_render(const cli_dist *d, atmos_plan *plan, const atmos_frame *f, atmos_image *img,
                             atmos_render_info *info)
{
    (void)d;
    return atmos_plan_render(plan, f, NULL, img, info);
}

atmos_status cli_dist_send(const cli_dist *d, const atmos_image *img, atmos_status st, const atmos_render_info *info)
{
    return (void)d, (void)img, (void)info, st;
}

atmos_status cli_dist_recv(const cli_dist *d, int from, atmos_image *img, atmos_render_info *info)
{
    return (void)d, (void)from, (void)img, (void)info, ATMOS_E_UNSUPPORTED;
}
