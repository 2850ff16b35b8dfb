#include "drivers/experiment.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/atomic_file.h"
#include "base/file_read.h"
#include "base/hash.h"
#include "base/memory.h"
#include "io/csv.h"
#include "io/images.h"
#include "io/plots.h"
#include "methods/registry.h"
#include "model/colour.h"
#include "methods/work_estimate.h"
#include "drivers/summary_table.h"
#include "base/progress.h"

#ifndef PPB_VERSION
#define PPB_VERSION "unknown"
#endif

/* Makes room for method m's results in ex (its result and companion, initialised with the
 * scene's layout and their ids): *out and *nout. */
static int begin_method(ppb_experiment *ex, const char *id, const ppb_method *m, ppb_result **out,
                        int *nout, ppb_err *err)
{
    *nout = m->also ? 2 : 1;
    if (ex->n + *nout > PPB_MAX_RESULTS)
        return ppb_fail(err, "too many results");
    ppb_layout lo = ppb_scene_layout(&ex->cfg->scene);
    *out = &ex->res[ex->n];
    if (ppb_result_init(&(*out)[0], id, &lo, err))
        return -1;
    if (*nout == 2 && ppb_result_init(&(*out)[1], m->also, &lo, err)) {
        ppb_result_free(&(*out)[0]);
        return -1;
    }
    ex->n += *nout;
    return 0;
}

/* Records how method m's run into ex's last nout results went: failed = its run's status, why
 * its reason, seconds its time. */
static void end_method(ppb_experiment *ex, const char *id, const ppb_method *m, int nout,
                       int failed, const ppb_err *why, double seconds, const ppb_run_ctx *ctx)
{
    ppb_result *out = &ex->res[ex->n - nout];
    if (failed) {
        /* This method's failure is its own; the others run on. */
        for (int i = 0; i < nout; i++)
            ppb_result_free(&out[i]);
        ex->n -= nout;
        if (ppb_interrupted()) {
            /* SIGINT/SIGTERM stopped it in its setup or solve, before it had a result: not a
             * failure, an incomplete method (no rows), as when it stops midway (below). */
            ex->partial = 1;
            if (ex->nincomplete < PPB_MAX_METHODS)
                snprintf(ex->incomplete[ex->nincomplete++], sizeof ex->incomplete[0], "%s", id);
            fprintf(stderr,
                    "%s: %s interrupted before it finished (%s): none of its rows written\n",
                    ex->cfg->name, id, why->msg);
            return;
        }
        if (ex->nfailed < PPB_MAX_METHODS) {
            snprintf(ex->failed[ex->nfailed], sizeof ex->failed[0], "%s", id);
            snprintf(ex->failed_why[ex->nfailed], sizeof ex->failed_why[0], "%s", why->msg);
            ex->nfailed++;
        }
        fprintf(stderr, "%s: %s failed: %s\n", ex->cfg->name, id, why->msg);
        return;
    }
    for (int i = 0; i < nout; i++) {
        ex->seconds[ex->n - nout + i] = seconds;
        ex->partial |= out[i].partial;
    }
    if (!ctx->quiet)
        fprintf(stderr, "%s: %s done in %.2f s (timings.csv: setup and kernel build included)\n",
                ex->cfg->name, id, seconds);
    if (out[0].partial && m->reference != 1) {
        /* A deterministic method stopped midway holds cells it never computed, which
         * would read as zero radiance, like data: none of its rows are written (README:
         * outputs). The Monte Carlo's partial result is an estimate from fewer photons: kept. */
        for (int i = 0; i < nout; i++)
            ppb_result_free(&out[i]);
        ex->n -= nout;
        if (ex->nincomplete < PPB_MAX_METHODS)
            snprintf(ex->incomplete[ex->nincomplete++], sizeof ex->incomplete[0], "%s", id);
        fprintf(stderr, "%s: %s interrupted before it finished: none of its rows written\n",
                ex->cfg->name, id);
    }
}

/* Runs method m under the config's id for it (an external method's descriptor has none). */
static int run_method(ppb_experiment *ex, const char *id, const ppb_method *m, ppb_run_ctx *ctx,
                      ppb_err *err)
{
    int nout;
    ppb_result *out;
    if (begin_method(ex, id, m, &out, &nout, err))
        return -1;
    if (!ctx->quiet)
        fprintf(stderr, "%s: %s ...\n", ex->cfg->name, id);
    double t0 = ppb_now();
    ppb_err why = {{0}};
    ctx->cfg = ex->cfg;
    ctx->prior = ex->res; /* what ran before it, for a method that combines others */
    ctx->nprior = ex->n - nout;
    ctx->self = m;
    int rc = m->run(ctx, out, &why);
    /* timings.csv's seconds (reference: Outputs): the method's whole run, from its start to its
     * result (setup, kernel builds, the reference cache, the work, reading back), the same
     * number said here; the progress lines time the work loop alone (mc: the trace). */
    end_method(ex, id, m, nout, rc != 0, &why, ppb_now() - t0, ctx);
    return 0;
}

const char *ppb_subset_name(int s)
{
    static const char *const names[PPB_NSUBSETS] = {"r", "g", "b", "y"};
    return s >= 0 && s < PPB_NSUBSETS ? names[s] : "?";
}

/* A colour experiment's method m run once for every channel (its run_channels): each channel's
 * results made in its own experiment, handed over as one array (method.h), and recorded in
 * each with the joint run's time. */
static int run_channels(ppb_colour *col, const char *id, const ppb_method *m, ppb_run_ctx *ctx,
                        ppb_err *err)
{
    ppb_result all[6];
    ppb_result *out[3];
    int nout = 0;
    memset(all, 0, sizeof all);
    for (int c = 0; c < 3; c++) {
        if (begin_method(&col->sub[c], id, m, &out[c], &nout, err)) {
            for (int d = 0; d < c; d++) /* the ones begun before are given back */
                end_method(&col->sub[d], id, m, nout, 1, &(ppb_err){"not run"}, 0, ctx);
            return -1;
        }
        memcpy(&all[2 * c], out[c], (size_t)nout * sizeof *out[c]);
    }
    if (!ctx->quiet)
        fprintf(stderr, "%s: %s (r, g, b at once) ...\n", col->sub[PPB_SUBSET_Y].cfg->name, id);
    double t0 = ppb_now();
    ppb_err why = {{0}};
    ctx->cfg = &col->cfg[0];
    ctx->prior = col->sub[0].res;
    ctx->nprior = col->sub[0].n - nout;
    ctx->self = m;
    int rc = m->run_channels(ctx, col->cfg, 3, all, &why);
    double seconds = ppb_now() - t0;
    for (int c = 0; c < 3; c++) {
        memcpy(out[c], &all[2 * c], (size_t)nout * sizeof *out[c]);
        end_method(&col->sub[c], id, m, nout, rc != 0, &why, seconds, ctx);
        if (m->reference == 1) { /* each channel's own reference file (provenance.txt) */
            ppb_experiment *s = &col->sub[c];
            snprintf(s->mc_reference, sizeof s->mc_reference, "%s", ctx->mc_channel_reference[c]);
            snprintf(s->mc_shipped_key, sizeof s->mc_shipped_key, "%s",
                     ctx->mc_channel_shipped_key[c]);
        }
    }
    return 0;
}

/* The luminance subset: for every result all three channels hold, their weighted sum
 * (model/colour.h); a method that failed or is incomplete in any channel is so in y. */
static int luminance(ppb_colour *col, ppb_err *err)
{
    ppb_experiment *y = &col->sub[PPB_SUBSET_Y];
    for (int i = 0; i < col->sub[0].n; i++) {
        const ppb_result *ch[3] = {&col->sub[0].res[i], NULL, NULL};
        double seconds = col->sub[0].seconds[i];
        for (int c = 1; c < 3; c++)
            for (int j = 0; j < col->sub[c].n && !ch[c]; j++)
                if (!strcmp(col->sub[c].res[j].method, ch[0]->method)) {
                    ch[c] = &col->sub[c].res[j];
                    seconds += col->sub[c].seconds[j];
                }
        if (!ch[1] || !ch[2])
            continue;
        if (y->n >= PPB_MAX_RESULTS)
            return ppb_fail(err, "too many results");
        if (ppb_result_luminance(ch, &y->res[y->n], err))
            return -1;
        y->seconds[y->n++] = seconds;
    }
    for (int c = 0; c < 3; c++) {
        const ppb_experiment *s = &col->sub[c];
        y->partial |= s->partial;
        for (int i = 0; i < s->nfailed && y->nfailed < PPB_MAX_METHODS; i++) {
            snprintf(y->failed[y->nfailed], sizeof y->failed[0], "%s", s->failed[i]);
            snprintf(y->failed_why[y->nfailed++], sizeof y->failed_why[0], "%s: %s",
                     ppb_subset_name(c), s->failed_why[i]);
        }
        for (int i = 0; i < s->nincomplete && y->nincomplete < PPB_MAX_METHODS; i++)
            snprintf(y->incomplete[y->nincomplete++], sizeof y->incomplete[0], "%s",
                     s->incomplete[i]);
    }
    return 0;
}

/* A colour experiment (experiment.h): each channel's config, every method per channel (or at
 * once, run_channels), then the luminance. */
static int compute_colour(ppb_experiment *ex, const ppb_config *cfg, ppb_run_ctx *ctx, ppb_err *err)
{
    ppb_colour *col = calloc(1, sizeof *col);
    if (!col)
        return ppb_fail(err, "out of memory");
    ex->colour = col;
    for (int c = 0; c < 3; c++) {
        if (ppb_config_channel(cfg, c, &col->cfg[c], err))
            return -1;
        col->sub[c].cfg = &col->cfg[c];
    }
    col->sub[PPB_SUBSET_Y].cfg = cfg;
    /* Every channel's result arrays and the luminance's are held at once. */
    double bytes = (double)PPB_NSUBSETS * ppb_work_results_bytes(cfg);
    char detail[160];
    snprintf(detail, sizeof detail,
             "its result arrays: radiance and standard error of %zu cells, for r, g, b and y",
             ppb_scene_layout(&cfg->scene).ncells);
    if (ppb_memory_check(bytes, cfg->memory_limit, "the colour experiment", detail, err))
        return -1;
    for (int c = 0; c < 3 && !ctx->quiet; c++)
        ppb_work_print(stderr, &col->cfg[c]);
    int i = 0;
    for (; i < cfg->nmethods && !ppb_interrupted(); i++) {
        const ppb_method *m = ppb_method_find(cfg, cfg->methods[i]);
        if (m->run_channels) {
            if (run_channels(col, cfg->methods[i], m, ctx, err))
                return -1;
            continue;
        }
        for (int c = 0; c < 3 && !ppb_interrupted(); c++) {
            ppb_experiment *s = &col->sub[c];
            ctx->mc_reference[0] = ctx->mc_shipped_key[0] = '\0';
            if (run_method(s, cfg->methods[i], m, ctx, err))
                return -1;
            if (m->reference == 1) { /* the channel's own reference file (provenance.txt) */
                snprintf(s->mc_reference, sizeof s->mc_reference, "%s", ctx->mc_reference);
                snprintf(s->mc_shipped_key, sizeof s->mc_shipped_key, "%s", ctx->mc_shipped_key);
            }
        }
    }
    ctx->prior = NULL;
    ctx->nprior = 0;
    ctx->cfg = cfg;
    for (; i < cfg->nmethods; i++) {
        ex->partial = 1;
        fprintf(stderr, "%s: %s skipped: interrupted before it started\n", cfg->name,
                cfg->methods[i]);
    }
    int any = 0;
    for (int c = 0; c < 3; c++) {
        ppb_experiment *s = &col->sub[c];
        ex->partial |= s->partial;
        s->partial |= ex->partial;
        any |= s->n > 0;
        if (ctx->ocl_open) {
            snprintf(s->device, sizeof s->device, "%s", ctx->ocl.name);
            ppb_ocl_versions_get(&ctx->ocl, &s->ocl_versions);
        }
    }
    if (luminance(col, err))
        return -1;
    ppb_experiment *y = &col->sub[PPB_SUBSET_Y];
    y->partial |= ex->partial;
    memcpy(y->device, col->sub[0].device, sizeof y->device);
    y->ocl_versions = col->sub[0].ocl_versions;
    memcpy(ex->device, y->device, sizeof ex->device);
    ex->ocl_versions = y->ocl_versions;
    /* The run's failures are every channel's, as y records them (`run` says them). */
    ex->nfailed = y->nfailed;
    memcpy(ex->failed, y->failed, sizeof ex->failed);
    memcpy(ex->failed_why, y->failed_why, sizeof ex->failed_why);
    if (!any && col->sub[0].nfailed > 0)
        return ppb_fail(err, "%s", col->sub[0].failed_why[0]);
    return 0;
}

int ppb_experiment_compute(ppb_experiment *ex, const ppb_config *cfg, ppb_run_ctx *ctx,
                           ppb_err *err)
{
    memset(ex, 0, sizeof *ex);
    ex->cfg = cfg;
    ctx->cfg = cfg;
    if (cfg->channel == PPB_CHANNEL_RGB)
        return compute_colour(ex, cfg, ctx, err);
    /* The result arrays are estimated and checked before any is allocated, and the
     * work is said before it starts (methods/work_estimate.h). */
    double bytes = ppb_work_results_bytes(cfg);
    char detail[128];
    snprintf(detail, sizeof detail, "its result arrays: radiance and standard error of %zu cells",
             ppb_scene_layout(&cfg->scene).ncells);
    if (ppb_memory_check(bytes, cfg->memory_limit, "the experiment", detail, err))
        return -1;
    if (!ctx->quiet)
        ppb_work_print(stderr, cfg);
    int i = 0;
    for (; i < cfg->nmethods && !ppb_interrupted(); i++)
        if (run_method(ex, cfg->methods[i], ppb_method_find(cfg, cfg->methods[i]), ctx, err))
            return -1;
    ctx->prior = NULL;
    ctx->nprior = 0;
    if (ppb_interrupted() && i < cfg->nmethods) {
        /* After an interrupt the methods not yet started are skipped, and said so; the outputs
         * of those that ran are written, marked partial (docs/reference.md, Exit codes). An
         * interrupt after the last method finished leaves no row missing: the set is not
         * partial (a method stopped midway marked it already). */
        ex->partial = 1;
        for (; i < cfg->nmethods; i++)
            fprintf(stderr, "%s: %s skipped: interrupted before it started\n", cfg->name,
                    cfg->methods[i]);
    }
    snprintf(ex->mc_reference, sizeof ex->mc_reference, "%s", ctx->mc_reference);
    snprintf(ex->mc_shipped_key, sizeof ex->mc_shipped_key, "%s", ctx->mc_shipped_key);
    if (ctx->ocl_open) {
        snprintf(ex->device, sizeof ex->device, "%s", ctx->ocl.name);
        ppb_ocl_versions_get(&ctx->ocl, &ex->ocl_versions);
    }
    if (ex->n == 0 && ex->nfailed > 0)
        return ppb_fail(err, "%s", ex->failed_why[0]);
    return 0;
}

void ppb_experiment_free(ppb_experiment *ex)
{
    for (int i = 0; i < ex->n; i++)
        ppb_result_free(&ex->res[i]);
    ex->n = 0;
    if (ex->colour) {
        for (int s = 0; s < PPB_NSUBSETS; s++)
            ppb_experiment_free(&ex->colour->sub[s]);
        free(ex->colour);
        ex->colour = NULL;
    }
}

const ppb_result *ppb_experiment_reference(const ppb_experiment *ex)
{
    for (int i = 0; i < ex->n; i++) {
        const ppb_method *m = ppb_method_find(ex->cfg, ex->res[i].method);
        if (m && m->reference == 1)
            return &ex->res[i];
    }
    return NULL;
}

/* The registry entry whose companion result is `id` (mc for mc1), or NULL. */
static const ppb_method *parent_of(const char *id)
{
    for (int i = 0; i < ppb_method_count(); i++) {
        const ppb_method *m = ppb_method_at(i);
        if (m->also && strcmp(m->also, id) == 0)
            return m;
    }
    return NULL;
}

/* Secondary references: exact answers other methods are also checked against -- a reference's
 * companion (mc1) and the slab solution (ppslab, reference == 2). */
static int is_secondary(const char *id)
{
    const ppb_method *m = ppb_method_find(NULL, id); /* built-in: no external method is one */
    const ppb_method *p = parent_of(id);
    return (m && m->reference == 2) || (p && p->reference == 1);
}

/* The result left out when measuring against ref: its companion, or its parent. */
static const char *skip_for(const ppb_result *ref)
{
    const ppb_method *m = ppb_method_find(NULL, ref->method); /* references are built-in */
    if (m && m->also)
        return m->also;
    const ppb_method *p = parent_of(ref->method);
    return p ? p->id : NULL;
}

/* The first line of provenance.txt: what marks a directory as a ppbench output set. */
const char ppb_provenance_mark[] = "# ppbench provenance";
#define provenance_mark ppb_provenance_mark

static void out_path(const char *dir, const char *file, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", dir, file);
}

static int write_timings(const ppb_experiment *ex, const char *dir, ppb_err *err)
{
    char path[PPB_PATH_MAX + 256];
    out_path(dir, "timings.csv", path, sizeof path);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    fprintf(af.f, "method,seconds\n");
    for (int i = 0; i < ex->n; i++)
        fprintf(af.f, "%s,%.4f\n", ex->res[i].method, ex->seconds[i]);
    return ppb_afile_commit(&af, err);
}

/* The lines every provenance.txt opens with: what wrote it, when, on which device, the build. */
static void provenance_head(FILE *f, const ppb_experiment *ex)
{
    char when[64];
    time_t now = time(NULL);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    fprintf(f, "%s: what produced the files beside this one\n", provenance_mark);
    fprintf(f, "ppbench.version = %s\nconfig.path = %s\ndate = %s\n", PPB_VERSION, ex->cfg->path,
            when);
    fprintf(f, "device = %s\npartial = %d\n", ex->device[0] ? ex->device : "(none)", ex->partial);
    ppb_provenance_write_build(f, ex->device[0] ? &ex->ocl_versions : NULL);
}

/* provenance.txt; fig: the figures left out (NULL before they are drawn). */
static int write_provenance(const ppb_experiment *ex, const char *dir, const ppb_figures *fig,
                            ppb_err *err)
{
    char path[PPB_PATH_MAX + 256];
    out_path(dir, "provenance.txt", path, sizeof path);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    provenance_head(af.f, ex);
    for (int i = 0; i < ex->n; i++)
        if (ex->res[i].photons)
            fprintf(af.f, "%s.photons_traced = %lld\n", ex->res[i].method, ex->res[i].photons);
    for (int i = 0; i < ex->n; i++)
        fprintf(af.f, "%s.seconds = %.4f\n", ex->res[i].method, ex->seconds[i]);
    if (ex->mc_reference[0]) /* docs/reference.md, "The reference cache" */
        fprintf(af.f, "mc.reference = %s\n", ex->mc_reference);
    if (ex->mc_shipped_key[0])
        fprintf(af.f, "mc.shipped_key = %s\n", ex->mc_shipped_key);
    /* radiance.csv's hash: score refuses a radiance.csv that is not this set's (Outputs) */
    char rpath[PPB_PATH_MAX + 256];
    out_path(dir, "radiance.csv", rpath, sizeof rpath);
    size_t rlen;
    char *rad = ppb_read_file(rpath, &rlen);
    if (rad)
        fprintf(af.f, "radiance.xxh64 = %016llx\n", (unsigned long long)ppb_hash64(rad, rlen));
    free(rad);
    for (int i = 0; i < ex->nfailed; i++)
        fprintf(af.f, "%s.failed = %s\n", ex->failed[i], ex->failed_why[i]);
    for (int i = 0; i < ex->nincomplete; i++)
        fprintf(af.f, "%s.incomplete = interrupted before it finished: no rows written\n",
                ex->incomplete[i]);
    if (fig) /* before the config: `ppbench score` reads the lines from experiment.name on */
        fputs(fig->text, af.f);
    ppb_config_write_readable(ex->cfg, af.f);
    return ppb_afile_commit(&af, err);
}

/* config.ini: the resolved config as an INI file, which `ppbench run` takes (a run
 * can be repeated from its own output set; docs/reference.md: Outputs). */
static int write_config_ini(const ppb_experiment *ex, const char *dir, ppb_err *err)
{
    char path[PPB_PATH_MAX + 256];
    out_path(dir, "config.ini", path, sizeof path);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    ppb_config_write_ini(ex->cfg, af.f);
    return ppb_afile_commit(&af, err);
}

static int write_comparisons(const ppb_experiment *ex, const char *dir, ppb_err *err)
{
    const ppb_scene *sc = &ex->cfg->scene;
    char path[PPB_PATH_MAX + 256];
    const ppb_result *ref = ppb_experiment_reference(ex);
    if (ref) {
        out_path(dir, "rms.csv", path, sizeof path);
        if (ppb_write_rms_csv(path, sc, ex->res, ex->n, ref, skip_for(ref), err))
            return -1;
        out_path(dir, "summary.csv", path, sizeof path);
        if (ppb_write_summary_csv(path, ex->res, ex->n, ref, skip_for(ref), err))
            return -1;
        out_path(dir, "regions.csv", path, sizeof path);
        if (ppb_write_regions_csv(path, sc, ex->res, ex->n, ref, skip_for(ref), err))
            return -1;
    }
    for (int i = 0; i < ex->n; i++) {
        if (!is_secondary(ex->res[i].method))
            continue;
        char file[128];
        snprintf(file, sizeof file, "summary_%s.csv", ex->res[i].method);
        out_path(dir, file, path, sizeof path);
        if (ppb_write_summary_csv(path, ex->res, ex->n, &ex->res[i], skip_for(&ex->res[i]), err))
            return -1;
    }
    return 0;
}

/* Whether the existing directory ad->path may be replaced: it is empty (but for temporaries,
 * which ppb_adir_clean sorts out) or its provenance.txt starts with mark (the kind of set
 * this command writes). */
static int check_owned(const ppb_adir *ad, const char *dir, const char *mark, ppb_err *err)
{
    DIR *d = opendir(ad->path);
    if (!d)
        return errno == ENOENT ? 0 : ppb_fail(err, "%s: cannot read: %s", dir, strerror(errno));
    char other[256] = "";
    struct dirent *de;
    while (!other[0] && (de = readdir(d)))
        if (strcmp(de->d_name, ".") && strcmp(de->d_name, "..") && !ppb_temp_pid(de->d_name, 0))
            snprintf(other, sizeof other, "%s", de->d_name);
    closedir(d);
    if (!other[0])
        return 0;
    char path[PPB_PATH_MAX + 256], line[128] = "";
    out_path(ad->path, "provenance.txt", path, sizeof path);
    FILE *f = fopen(path, "r");
    if (f) {
        if (!fgets(line, sizeof line, f))
            line[0] = '\0';
        fclose(f);
    }
    if (!strncmp(line, mark, strlen(mark)) && line[strlen(mark)] == ':')
        return 0;
    return ppb_fail(err,
                    "%s: holds files ppbench did not write as this command's output (%s; no "
                    "provenance.txt starting \"%s:\"): it replaces its whole output directory, "
                    "so it will not take this one; give an empty or new directory",
                    dir, other, mark);
}

/* The lock files this process holds (claim_out: at most one a config), by device and inode:
 * the same directory may be named first relative, while its parent does not exist yet, and
 * then absolute, and a second flock of the same file would refuse this very process. */
static struct {
    dev_t dev;
    ino_t ino;
} locked[64];
static int nlocked;

/* An exclusive lock on .<name>.lock beside the directory (hidden: a listing of the parent shows
 * the output directories alone), held until the process exits: a
 * second process claiming the same directory is refused at its start, before any work, instead
 * of computing and then losing the swap (docs/reference.md: Outputs). */
static int lock_out(const ppb_adir *ad, const char *dir, ppb_err *err)
{
    char path[PPB_PATH_MAX + 16], parent[PPB_PATH_MAX + 16];
    snprintf(parent, sizeof parent, "%s", ad->path);
    char *slash = strrchr(parent, '/');
    const char *base = slash ? slash + 1 : parent;
    if (slash)
        *slash = '\0';
    if ((size_t)snprintf(path, sizeof path, "%s/.%s.lock",
                         slash ? (slash == parent ? "" : parent) : ".", base) >= sizeof path)
        return ppb_fail(err, "%s: path too long", dir);
    if (slash && slash != parent && ppb_mkdirs(parent, err))
        return -1;
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return ppb_fail(err, "%s: cannot take its lock %s: %s", dir, path, strerror(e));
    }
    for (int i = 0; i < nlocked; i++)
        if (locked[i].dev == st.st_dev && locked[i].ino == st.st_ino) {
            close(fd); /* held already, by this process */
            return 0;
        }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        int e = errno;
        close(fd);
        if (e == EWOULDBLOCK)
            return ppb_fail(err,
                            "%s: another ppbench is writing it (it holds %s); wait for it or "
                            "give another directory",
                            dir, path);
        return ppb_fail(err, "%s: cannot lock %s: %s", dir, path, strerror(e));
    }
    if (nlocked < 64) { /* the descriptor stays open: the lock lasts as long as the process */
        locked[nlocked].dev = st.st_dev;
        locked[nlocked++].ino = st.st_ino;
    }
    return 0;
}

/* A symbolic link whose target does not exist: refused, rather than replaced by a directory
 * (the link silently gone, its target never written). */
static int check_not_dangling(const char *dir, ppb_err *err)
{
    struct stat st;
    char buf[PPB_PATH_MAX];
    snprintf(buf, sizeof buf, "%s", dir);
    for (size_t n = strlen(buf); n > 1 && buf[n - 1] == '/'; n--)
        buf[n - 1] = '\0';
    if (lstat(buf, &st) == 0 && S_ISLNK(st.st_mode) && stat(buf, &st) != 0)
        return ppb_fail(err,
                        "%s: a symbolic link to nothing (%s): give the directory it should "
                        "name, or remove the link",
                        dir, strerror(errno));
    return 0;
}

int ppb_out_claim(const char *dir, const char *mark, ppb_adir *ad, ppb_err *err)
{
    if (check_not_dangling(dir, err) || ppb_adir_name(ad, dir, err) ||
        check_owned(ad, dir, mark, err) || lock_out(ad, dir, err))
        return -1;
    return ppb_adir_clean(ad, err);
}

/* The output directory named and claimed: see experiment.h. */
static int claim_out(const char *dir, ppb_adir *ad, ppb_err *err)
{
    return ppb_out_claim(dir, provenance_mark, ad, err);
}

int ppb_experiment_claim_out(const char *dir, ppb_err *err)
{
    ppb_adir ad;
    return claim_out(dir, &ad, err);
}

/* A file of the staged set found incomplete (ppb_dir_verify): a figure's is left out, as a
 * figure that failed; any other fails the write (the previous set stays). */
static int bad_file(const char *rel, const char *why, void *ctx, ppb_err *err)
{
    const ppb_adir *ad = ((void **)ctx)[0];
    ppb_figures *fig = ((void **)ctx)[1];
    size_t n = strlen(rel);
    int figure = (!strncmp(rel, "plots/", 6) || !strncmp(rel, "images/", 7)) && n > 4 &&
                 (!strcmp(rel + n - 4, ".png") || !strcmp(rel + n - 4, ".pdf"));
    if (!figure)
        return ppb_fail(err, "%s", why);
    char path[PPB_PATH_MAX + 700], name[600];
    snprintf(name, sizeof name, "%.*s", (int)n - 4, rel);
    for (int t = 0; t < 2; t++) { /* the figure goes whole: its PNG and its PDF */
        snprintf(path, sizeof path, "%s/%s.%s", ad->tmp, name, t ? "pdf" : "png");
        remove(path);
    }
    ppb_figures_fail(fig, name, why);
    return 0;
}

/* Every file of the output set, under ad->tmp: the data first (any failure fails the write),
 * then the images and figures (one that fails is said, recorded in provenance.txt and left
 * out; reference: Outputs), then every file is checked complete before the set may be put in
 * place. */
static int write_set(const ppb_experiment *ex, const ppb_adir *ad, ppb_err *err)
{
    const char *dir = ad->tmp;
    char path[PPB_PATH_MAX + 256];
    out_path(dir, "radiance.csv", path, sizeof path);
    if (ppb_write_radiance_csv(path, &ex->cfg->scene, ex->res, ex->n, err))
        return -1;
    out_path(dir, "totals.csv", path, sizeof path);
    if (ppb_write_totals_csv(path, ex->res, ex->n, err))
        return -1;
    out_path(dir, "angular.csv", path, sizeof path);
    if (ppb_write_angular_csv(path, &ex->cfg->scene, ex->res, ex->n, err))
        return -1;
    if (write_comparisons(ex, dir, err) || write_timings(ex, dir, err))
        return -1;
    for (int i = 0; i < ex->n; i++) /* a method's own outputs (rte2d_refinements.csv) */
        if (ppb_result_write_extra(&ex->res[i], dir, err))
            return -1;
    if (write_provenance(ex, dir, NULL, err) || write_config_ini(ex, dir, err))
        return -1;
    ppb_figures fig = {.who = ex->cfg->name, .staged = ad->tmp, .final = ad->path};
    const ppb_result *ref = ppb_experiment_reference(ex);
    const ppb_image_meta meta = {ex->cfg->name, PPB_VERSION, ex->cfg->mc.seed, ex->cfg->mc.photons};
    ppb_err why;
    if (ppb_images_write(dir, &ex->cfg->scene, &meta, ex->res, ex->n,
                         ref ? (int)(ref - ex->res) : -1, &why)) {
        /* a part of the images would be drawn into figures as if whole: none are kept */
        out_path(dir, "images", path, sizeof path);
        ppb_err ignored;
        ppb_remove_tree(path, &ignored);
        ppb_figures_fail(&fig, "images", why.msg);
    }
    /* Last: the figures read the files above. Then each method's own, once per method. */
    ppb_plots_write(dir, ref ? ref->method : NULL, &fig);
    for (int i = 0; i < ex->n; i++) {
        const ppb_method *m = ppb_method_find(ex->cfg, ex->res[i].method);
        int first = 1;
        for (int j = 0; j < i; j++)
            first &= ppb_method_find(ex->cfg, ex->res[j].method) != m;
        if (m && m->draw && first)
            m->draw(dir, ex->cfg->name, &fig);
    }
    void *ctx[2] = {(void *)ad, &fig};
    if (ppb_dir_verify(dir, bad_file, ctx, err))
        return -1;
    if (fig.nfailed && write_provenance(ex, dir, &fig, err))
        return -1;
    return 0;
}

/* The subsets' file `file` (summary.csv, timings.csv) as one table with a first column
 * `channel` (r, g, b, y): the rows of each subset that has the file, in subset order. */
static int write_channel_table(const char *dir, const char *file, ppb_err *err)
{
    char path[PPB_PATH_MAX + 256];
    out_path(dir, file, path, sizeof path);
    ppb_afile af;
    int any = 0;
    for (int s = 0; s < PPB_NSUBSETS; s++) {
        char sub[PPB_PATH_MAX + 256];
        snprintf(sub, sizeof sub, "%s/%s/%s", dir, ppb_subset_name(s), file);
        size_t len;
        char *text = ppb_read_file(sub, &len);
        if (!text)
            continue;
        if (!any && ppb_afile_open(&af, path, err)) {
            free(text);
            return -1;
        }
        char *line = text, *next;
        for (int row = 0; line && *line; row++, line = next) {
            next = strchr(line, '\n');
            if (next)
                *next++ = '\0';
            if (row == 0 && !any)
                fprintf(af.f, "channel,%s\n", line);
            else if (row > 0)
                fprintf(af.f, "%s,%s\n", ppb_subset_name(s), line);
        }
        any = 1;
        free(text);
    }
    return any ? ppb_afile_commit(&af, err) : 0;
}

/* The colour set's provenance.txt: what the subsets beside it are, each channel's reference
 * (each subset's own provenance.txt says the rest); fig: the figures left out. */
static int write_colour_provenance(const ppb_experiment *ex, const char *dir,
                                   const ppb_figures *fig, ppb_err *err)
{
    char path[PPB_PATH_MAX + 256];
    out_path(dir, "provenance.txt", path, sizeof path);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    provenance_head(af.f, ex);
    fprintf(af.f,
            "colour.subsets = r g b y (an output set each: the channels' and the luminance's)\n"
            "colour.primaries = Rec. 709 / sRGB, linear (the material's R, G, B channels)\n"
            "colour.luminance = %.4f R + %.4f G + %.4f B\n",
            ppb_luma[0], ppb_luma[1], ppb_luma[2]);
    const ppb_colour *col = ex->colour;
    for (int c = 0; c < 3; c++) {
        const ppb_experiment *s = &col->sub[c];
        if (s->mc_reference[0])
            fprintf(af.f, "%s.mc.reference = %s\n", ppb_subset_name(c), s->mc_reference);
        if (s->mc_shipped_key[0])
            fprintf(af.f, "%s.mc.shipped_key = %s\n", ppb_subset_name(c), s->mc_shipped_key);
    }
    const ppb_experiment *y = &col->sub[PPB_SUBSET_Y];
    for (int i = 0; i < y->nfailed; i++)
        fprintf(af.f, "%s.failed = %s\n", y->failed[i], y->failed_why[i]);
    if (fig)
        fputs(fig->text, af.f);
    ppb_config_write_readable(ex->cfg, af.f);
    return ppb_afile_commit(&af, err);
}

/* A colour experiment's set (experiment.h): each subset written as a grey set into its own
 * directory of the staging, then the colour files beside them. */
static int write_colour_set(const ppb_experiment *ex, const ppb_adir *ad, ppb_err *err)
{
    const ppb_colour *col = ex->colour;
    const char *dir = ad->tmp;
    for (int s = 0; s < PPB_NSUBSETS; s++) {
        ppb_adir sub = {0};
        if ((size_t)snprintf(sub.path, sizeof sub.path, "%s/%s", ad->path, ppb_subset_name(s)) >=
                sizeof sub.path ||
            (size_t)snprintf(sub.tmp, sizeof sub.tmp, "%s/%s", ad->tmp, ppb_subset_name(s)) >=
                sizeof sub.tmp)
            return ppb_fail(err, "%s: path too long for its channel subsets", ad->path);
        sub.made = 1;
        if (ppb_mkdirs(sub.tmp, err) || write_set(&col->sub[s], &sub, err))
            return -1;
    }
    if (write_channel_table(dir, "summary.csv", err) ||
        write_channel_table(dir, "timings.csv", err) ||
        write_colour_provenance(ex, dir, NULL, err) || write_config_ini(ex, dir, err))
        return -1;
    ppb_figures fig = {.who = ex->cfg->name, .staged = ad->tmp, .final = ad->path};
    /* The pictures of the results every channel holds, index by index. */
    static ppb_result res[3][PPB_MAX_RESULTS];
    const ppb_result *rows[3] = {res[0], res[1], res[2]};
    int n = 0, ref = -1;
    const ppb_result *cref = ppb_experiment_reference(&col->sub[0]);
    for (int i = 0; i < col->sub[0].n; i++) {
        const char *id = col->sub[0].res[i].method;
        int found = 1;
        res[0][n] = col->sub[0].res[i];
        for (int c = 1; c < 3; c++) {
            int j = 0;
            while (j < col->sub[c].n && strcmp(col->sub[c].res[j].method, id))
                j++;
            if (j == col->sub[c].n)
                found = 0;
            else
                res[c][n] = col->sub[c].res[j];
        }
        if (!found)
            continue;
        if (cref && !strcmp(id, cref->method))
            ref = n;
        n++;
    }
    const ppb_image_meta meta = {ex->cfg->name, PPB_VERSION, ex->cfg->mc.seed, ex->cfg->mc.photons};
    ppb_err why;
    if (ppb_images_write_colour(dir, &col->cfg[0].scene, &meta, ex->cfg->material,
                                ex->cfg->unit == PPB_UNIT_MM ? "mm" : "mfp", rows, n, ref, &why)) {
        char path[PPB_PATH_MAX + 256];
        out_path(dir, "images", path, sizeof path);
        ppb_err ignored;
        ppb_remove_tree(path, &ignored);
        ppb_figures_fail(&fig, "images", why.msg);
    }
    ppb_plots_write(dir, cref ? cref->method : NULL, &fig);
    void *ctx[2] = {(void *)ad, &fig};
    if (ppb_dir_verify(dir, bad_file, ctx, err))
        return -1;
    if (fig.nfailed && write_colour_provenance(ex, dir, &fig, err))
        return -1;
    return 0;
}

void ppb_experiment_print_summary(const ppb_experiment *ex, FILE *f)
{
    for (int s = 0; ex->colour && s < PPB_NSUBSETS; s++) {
        const ppb_experiment *sub = &ex->colour->sub[s];
        const ppb_result *ref = ppb_experiment_reference(sub);
        char name[192];
        snprintf(name, sizeof name, "%s (%s)", ex->cfg->name, ppb_subset_name(s));
        if (ref)
            ppb_summary_table_print(f, name, sub->res, sub->n, ref, skip_for(ref));
    }
    const ppb_result *ref = ppb_experiment_reference(ex);
    if (ref)
        ppb_summary_table_print(f, ex->cfg->name, ex->res, ex->n, ref, skip_for(ref));
}

int ppb_experiment_write(const ppb_experiment *ex, ppb_err *err)
{
    /* The set is written whole into a staging directory beside the output directory
     * and swapped into place, so a failure midway (a full disk) leaves the previous set as it
     * was and a smaller set never sits beside a previous run's files. */
    ppb_adir ad;
    if (claim_out(ex->cfg->out_dir, &ad, err) || ppb_adir_begin(&ad, err))
        return -1;
    if (ex->colour ? write_colour_set(ex, &ad, err) : write_set(ex, &ad, err)) {
        ppb_adir_abort(&ad);
        return -1;
    }
    if (ppb_adir_commit(&ad, err))
        return -1;
    if (ex->nfailed > 0) /* a colour run's: every channel's, named by channel */
        return ppb_fail(err, "%d method(s) failed, the others' outputs are written: %s: %s",
                        ex->nfailed, ex->failed[0], ex->failed_why[0]);
    return 0;
}
