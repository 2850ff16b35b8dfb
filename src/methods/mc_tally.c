#include "methods/mc_tally.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"
#include "base/hash.h"

/* Version 02: the fingerprint became base/hash.h's XXH3 (01 held FNV-1a), so a version 01 file
 * is refused as such instead of failing every merge with "different scenes". */
static const char magic[8] = {'P', 'P', 'B', 'M', 'C', 'T', '0', '2'};

/* A hash (base/hash.h) of the canonical text of every setting that changes a photon's path or
 * its cell, so tallies from different scenes (or bin layouts) can never be merged by mistake. */
uint64_t ppb_mc_scene_fingerprint(const ppb_scene *sc)
{
    char buf[512];
    int n = snprintf(buf, sizeof buf,
                     "%d %.17g %.17g %d %d %.17g %.17g %.17g %d %.17g %.17g %.17g "
                     "%.17g %d %d",
                     (int)sc->geometry, sc->geometry == PPB_GEOM_TUBE ? sc->width : 0.0, sc->height,
                     sc->segments_top, sc->segments_side, sc->sigma_t, sc->albedo, sc->g, sc->step,
                     sc->step_x, sc->sigma_t_right, sc->albedo_right, sc->theta_deg, sc->ntheta,
                     sc->nphi);
    return ppb_hash64(buf, n < (int)sizeof buf ? (size_t)n : sizeof buf - 1);
}

static int alloc_arrays(ppb_mc_tallies *t, ppb_err *err)
{
    size_t nb = (size_t)t->batches;
    t->photons = calloc(nb, sizeof *t->photons);
    t->cells = calloc(nb * PPB_MC_NTALLY * t->ncells, sizeof *t->cells);
    t->totals = calloc(nb * PPB_MC_NTOT, sizeof *t->totals);
    if (!t->photons || !t->cells || !t->totals) {
        ppb_mc_tallies_free(t);
        return ppb_fail(err, "mc: out of memory for tallies (%d batches x %zu cells)", t->batches,
                        t->ncells);
    }
    return 0;
}

int ppb_mc_tallies_init(ppb_mc_tallies *t, const ppb_scene *sc, uint64_t seed, int batches,
                        ppb_err *err)
{
    memset(t, 0, sizeof *t);
    if (batches < 1)
        return ppb_fail(err, "mc: batches must be at least 1 (got %d)", batches);
    ppb_layout lo = ppb_scene_layout(sc);
    t->fingerprint = ppb_mc_scene_fingerprint(sc);
    t->seed = seed;
    t->batches = batches;
    t->ncells = lo.ncells;
    return alloc_arrays(t, err);
}

void ppb_mc_tallies_free(ppb_mc_tallies *t)
{
    free(t->photons);
    free(t->cells);
    free(t->totals);
    t->photons = t->cells = t->totals = NULL;
}

uint64_t ppb_mc_tallies_photons(const ppb_mc_tallies *t)
{
    uint64_t n = 0;
    for (int b = 0; b < t->batches; b++)
        n += t->photons[b];
    return n;
}

void ppb_mc_tallies_count_range(ppb_mc_tallies *t, uint64_t first, uint64_t count)
{
    uint64_t nb = (uint64_t)t->batches;
    for (uint64_t b = 0; b < nb; b++) {
        /* photons i in [first, first + count) with i % nb == b */
        uint64_t off = (b + nb - first % nb) % nb; /* first such i is first + off */
        t->photons[b] += off < count ? (count - off - 1) / nb + 1 : 0;
    }
}

static int add_array(uint64_t *dst, const uint64_t *src, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (dst[i] + src[i] < dst[i])
            return -1;
        dst[i] += src[i];
    }
    return 0;
}

int ppb_mc_tallies_add(ppb_mc_tallies *dst, const ppb_mc_tallies *src, ppb_err *err)
{
    if (dst->fingerprint != src->fingerprint || dst->ncells != src->ncells)
        return ppb_fail(err, "mc merge: tallies come from different scenes or bin settings");
    if (dst->seed != src->seed)
        return ppb_fail(err, "mc merge: tallies have different seeds (%llu vs %llu)",
                        (unsigned long long)dst->seed, (unsigned long long)src->seed);
    if (dst->batches != src->batches)
        return ppb_fail(err, "mc merge: tallies have different batch counts (%d vs %d)",
                        dst->batches, src->batches);
    size_t nb = (size_t)dst->batches;
    if (add_array(dst->photons, src->photons, nb) ||
        add_array(dst->cells, src->cells, nb * PPB_MC_NTALLY * dst->ncells) ||
        add_array(dst->totals, src->totals, nb * PPB_MC_NTOT))
        return ppb_fail(err, "mc merge: a 64-bit tally overflowed (too many photons per batch)");
    return 0;
}

/* Little-endian uint64 I/O, byte by byte, so the file is the same on every host. */
static int put_u64s(FILE *f, const uint64_t *v, size_t n)
{
    unsigned char b[8];
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 8; k++)
            b[k] = (unsigned char)(v[i] >> (8 * k));
        if (fwrite(b, 1, 8, f) != 8)
            return -1;
    }
    return 0;
}

static int get_u64s(FILE *f, uint64_t *v, size_t n)
{
    unsigned char b[8];
    for (size_t i = 0; i < n; i++) {
        if (fread(b, 1, 8, f) != 8)
            return -1;
        uint64_t x = 0;
        for (int k = 0; k < 8; k++)
            x |= (uint64_t)b[k] << (8 * k);
        v[i] = x;
    }
    return 0;
}

int ppb_mc_tallies_save(const ppb_mc_tallies *t, const char *path, ppb_err *err)
{
    ppb_afile af;
    if (ppb_afile_open(&af, path, err))
        return -1;
    FILE *f = af.f;
    uint64_t head[4] = {t->fingerprint, t->seed, (uint64_t)t->batches, (uint64_t)t->ncells};
    size_t nb = (size_t)t->batches;
    int bad = fwrite(magic, 1, sizeof magic, f) != sizeof magic || put_u64s(f, head, 4) ||
              put_u64s(f, t->photons, nb) || put_u64s(f, t->totals, nb * PPB_MC_NTOT) ||
              put_u64s(f, t->cells, nb * PPB_MC_NTALLY * t->ncells);
    if (bad) {
        ppb_afile_abort(&af);
        return ppb_fail(err, "%s: write failed: %s", path, strerror(errno));
    }
    return ppb_afile_commit(&af, err);
}

int ppb_mc_tallies_load(ppb_mc_tallies *t, const char *path, ppb_err *err)
{
    memset(t, 0, sizeof *t);
    FILE *f = fopen(path, "rb");
    if (!f)
        return ppb_fail(err, "%s: cannot read: %s", path, strerror(errno));
    char m[8];
    uint64_t head[4];
    if (fread(m, 1, sizeof m, f) != sizeof m || memcmp(m, magic, 6) != 0 || get_u64s(f, head, 4)) {
        fclose(f);
        return ppb_fail(err, "%s: not a ppbench Monte Carlo tally file", path);
    }
    if (memcmp(m, magic, sizeof m) != 0) {
        fclose(f);
        return ppb_fail(err,
                        "%s: tally file version %.2s, this ppbench reads %.2s: run the shard again",
                        path, m + 6, magic + 6);
    }
    if (head[2] < 1 || head[2] > (1u << 20) || head[3] > ((uint64_t)1 << 32)) {
        fclose(f);
        return ppb_fail(err, "%s: implausible header (batches %llu, cells %llu)", path,
                        (unsigned long long)head[2], (unsigned long long)head[3]);
    }
    t->fingerprint = head[0];
    t->seed = head[1];
    t->batches = (int)head[2];
    t->ncells = (size_t)head[3];
    if (alloc_arrays(t, err)) {
        fclose(f);
        return -1;
    }
    size_t nb = (size_t)t->batches;
    int bad = get_u64s(f, t->photons, nb) || get_u64s(f, t->totals, nb * PPB_MC_NTOT) ||
              get_u64s(f, t->cells, nb * PPB_MC_NTALLY * t->ncells) || fgetc(f) != EOF;
    fclose(f);
    if (bad) {
        ppb_mc_tallies_free(t);
        return ppb_fail(err, "%s: truncated or oversized tally file", path);
    }
    return 0;
}

/* Mean and standard error of per-photon quantities whose batch b sums are sum(b) (in units of
 * the fixed-point scale): the mean over all photons, and the standard error from the spread of
 * the batch means (batches with no photons are skipped). */
typedef struct batch_stat {
    double mean, se;
} batch_stat;

static batch_stat batch_mean(const ppb_mc_tallies *t, const uint64_t *base, size_t stride,
                             double scale)
{
    batch_stat st = {0, 0};
    uint64_t n = 0;
    double sum = 0;
    int used = 0;
    for (int b = 0; b < t->batches; b++) {
        if (!t->photons[b])
            continue;
        sum += (double)base[(size_t)b * stride];
        n += t->photons[b];
        used++;
    }
    if (!n)
        return st;
    st.mean = sum * scale / (double)n;
    if (used < 2)
        return st;
    double ss = 0;
    for (int b = 0; b < t->batches; b++) {
        if (!t->photons[b])
            continue;
        double mb = (double)base[(size_t)b * stride] * scale / (double)t->photons[b];
        ss += (mb - st.mean) * (mb - st.mean);
    }
    st.se = sqrt(ss / ((double)used * (double)(used - 1)));
    return st;
}

void ppb_mc_tallies_totals(const ppb_mc_tallies *t, const ppb_scene *sc, int once,
                           ppb_mc_totals_stats *st)
{
    memset(st, 0, sizeof *st);
    const double unit = 1.0 / PPB_MC_FIXED_SCALE;
    ppb_layout lo = ppb_scene_layout(sc);
    size_t nb = (size_t)t->batches;
    size_t tstride = (size_t)PPB_MC_NTALLY * t->ncells;
    /* Per-batch sums of each surface (integers, exact), then the batch statistics. */
    uint64_t *surf = calloc(nb * PPB_NSURF, sizeof *surf);
    uint64_t *sides = calloc(nb, sizeof *sides);
    if (!surf || !sides) {
        free(surf), free(sides);
        return;
    }
    for (size_t b = 0; b < nb; b++) {
        const uint64_t *c = t->cells + b * tstride + (size_t)(once ? 1 : 0) * t->ncells;
        for (int s = 0; s < lo.nsurf; s++) {
            size_t i0 = ppb_cell(&lo, s, 0, 0), i1 = i0 + (size_t)lo.nseg[s] * lo.nbins;
            for (size_t i = i0; i < i1; i++)
                surf[b * PPB_NSURF + (size_t)s] += c[i];
        }
        sides[b] = surf[b * PPB_NSURF + PPB_S3] + surf[b * PPB_NSURF + PPB_S4];
    }
    batch_stat R = batch_mean(t, surf + PPB_S1, PPB_NSURF, unit);
    batch_stat T = batch_mean(t, surf + PPB_S2, PPB_NSURF, unit);
    batch_stat S = batch_mean(t, sides, 1, unit);
    batch_stat B = batch_mean(t, t->totals + PPB_MC_T_BALLISTIC, PPB_MC_NTOT, unit);
    batch_stat C = batch_mean(t, t->totals + PPB_MC_T_CAPTURE, PPB_MC_NTOT, unit);
    batch_stat E = batch_mean(t, t->totals + PPB_MC_T_EVENTS, PPB_MC_NTOT, 1.0);
    /* The roulette balance (loss - gain) is signed, so it is tallied as two unsigned sums; its
     * mean is the difference of their means and its spread comes from the batch differences. */
    batch_stat L = batch_mean(t, t->totals + PPB_MC_T_RLOSS, PPB_MC_NTOT, unit);
    batch_stat G = batch_mean(t, t->totals + PPB_MC_T_RGAIN, PPB_MC_NTOT, unit);
    double net = L.mean - G.mean, ss_net = 0, ss_abs = 0;
    int used = 0;
    for (size_t b = 0; b < nb; b++) {
        if (!t->photons[b])
            continue;
        const uint64_t *tb = t->totals + b * PPB_MC_NTOT;
        double n = (double)t->photons[b];
        double rb = ((double)tb[PPB_MC_T_RLOSS] - (double)tb[PPB_MC_T_RGAIN]) * unit / n;
        double ab = rb + (double)tb[PPB_MC_T_CAPTURE] * unit / n;
        ss_net += (rb - net) * (rb - net);
        ss_abs += (ab - (net + C.mean)) * (ab - (net + C.mean));
        used++;
    }
    double dof = used > 1 ? (double)used * (double)(used - 1) : 0;
    st->mean.R = R.mean, st->se.R = R.se;
    st->mean.T = T.mean, st->se.T = T.se;
    st->mean.sides = S.mean, st->se.sides = S.se;
    st->mean.ballistic = B.mean, st->se.ballistic = B.se;
    st->capture = C.mean, st->capture_se = C.se;
    st->roulette = net, st->roulette_se = dof > 0 ? sqrt(ss_net / dof) : 0;
    st->events_per_photon = E.mean;
    if (once) {
        /* mc1 holds only the once-scattered exits: what it does not hold is not "absorbed"
         * in any tracked sense, so the writer completes it as 1 - the rest (reference: Bins). */
        st->mean.absorbed_tracked = 0;
        ppb_totals_complete(&st->mean);
    } else {
        st->mean.absorbed = net + C.mean;
        st->se.absorbed = dof > 0 ? sqrt(ss_abs / dof) : 0;
        st->mean.absorbed_tracked = 1;
    }
    free(surf), free(sides);
}

static void cells_to_result(const ppb_mc_tallies *t, const ppb_scene *sc, int once, ppb_result *r)
{
    const ppb_layout *lo = &r->layout;
    double power = ppb_scene_power_in(sc);
    size_t tstride = (size_t)PPB_MC_NTALLY * t->ncells;
    const uint64_t *base = t->cells + (size_t)(once ? 1 : 0) * t->ncells;
    for (int s = 0; s < lo->nsurf; s++) {
        /* Each photon carries lit x cos(theta_L) / N of the entering power (reference: Light); a
         * cell's radiance is its energy over segment length x projected solid angle. */
        double scale = power / ppb_scene_cell_measure(sc, s) / PPB_MC_FIXED_SCALE;
        for (int seg = 0; seg < lo->nseg[s]; seg++)
            for (int k = 0; k < lo->nbins; k++) {
                size_t c = ppb_cell(lo, s, seg, k);
                batch_stat st = batch_mean(t, base + c, tstride, scale);
                r->radiance[c] = st.mean;
                r->se[c] = st.se;
            }
    }
    ppb_mc_totals_stats ts;
    ppb_mc_tallies_totals(t, sc, once, &ts);
    r->totals = ts.mean;
    r->photons = (long long)ppb_mc_tallies_photons(t);
}

void ppb_mc_tallies_to_results(const ppb_mc_tallies *t, const ppb_scene *sc, ppb_result *mc,
                               ppb_result *mc1)
{
    if (mc)
        cells_to_result(t, sc, 0, mc);
    if (mc1)
        cells_to_result(t, sc, 1, mc1);
}
