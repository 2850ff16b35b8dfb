#include "methods/mc/mc_tally.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "base/atomic_file.h"
#include "base/file_read.h"
#include "base/hash.h"
#include "kernels/ppb_fresnel.h"

/* Version 02: the fingerprint became base/hash.h's XXH3 (01 held FNV-1a), so a version 01 file
 * is refused as such instead of failing every merge with "different scenes". Version 03: the
 * header records the photon range the file holds (a merge refuses duplicates, overlaps and
 * gaps) and a checksum ends the file (a flipped bit is refused). */
static const char magic[8] = {'P', 'P', 'B', 'M', 'C', 'T', '0', '3'};
enum { NHEAD = 8 };

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
    /* n joins the text only where it acts, so n = 1 fingerprints are those of before. */
    if (sc->n > 1.0 && n > 0 && n < (int)sizeof buf)
        n += snprintf(buf + n, sizeof buf - (size_t)n, " n=%.17g", sc->n);
    /* The searchlight's keys join it once any differs from its default (lit = face, x0 = 0,
     * width = 1; reference: Light), so the whole face's fingerprints too are those of before. */
    if ((sc->searchlight || sc->light_x0 != 0.0 || sc->light_width != 1.0) && n > 0 &&
        n < (int)sizeof buf)
        n += snprintf(buf + n, sizeof buf - (size_t)n, " light=%d,%.17g,%.17g", sc->searchlight,
                      sc->light_x0, sc->light_width);
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

int ppb_mc_tallies_range_matches(const ppb_mc_tallies *t)
{
    uint64_t nb = (uint64_t)t->batches;
    for (uint64_t b = 0; b < nb; b++) {
        uint64_t off = (b + nb - t->first % nb) % nb; /* as ppb_mc_tallies_count_range */
        if (t->photons[b] != (off < t->count ? (t->count - off - 1) / nb + 1 : 0))
            return 0;
    }
    return 1;
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

int ppb_mc_tallies_equal(const ppb_mc_tallies *a, const ppb_mc_tallies *b)
{
    size_t nb = (size_t)a->batches;
    return a->batches == b->batches && a->ncells == b->ncells &&
           !memcmp(a->photons, b->photons, nb * sizeof *a->photons) &&
           !memcmp(a->totals, b->totals, nb * PPB_MC_NTOT * sizeof *a->totals) &&
           !memcmp(a->cells, b->cells, nb * PPB_MC_NTALLY * a->ncells * sizeof *a->cells);
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

/* Little-endian uint64 I/O in blocks, so the file is the same on every host; every byte
 * written or read before the checksum goes through the hasher. */
enum { BLOCK = 4096 };

typedef struct tally_io {
    FILE *f;
    ppb_hasher *h;
} tally_io;

static int put_bytes(tally_io *io, const void *b, size_t n)
{
    ppb_hash64_update(io->h, b, n);
    return fwrite(b, 1, n, io->f) == n ? 0 : -1;
}

static int put_u64s(tally_io *io, const uint64_t *v, size_t n)
{
    unsigned char b[8 * BLOCK];
    while (n > 0) {
        size_t k = n < BLOCK ? n : BLOCK;
        for (size_t i = 0; i < k; i++)
            for (int j = 0; j < 8; j++)
                b[8 * i + (size_t)j] = (unsigned char)(v[i] >> (8 * j));
        if (put_bytes(io, b, 8 * k))
            return -1;
        v += k, n -= k;
    }
    return 0;
}

static int get_u64s(tally_io *io, uint64_t *v, size_t n)
{
    unsigned char b[8 * BLOCK];
    while (n > 0) {
        size_t k = n < BLOCK ? n : BLOCK;
        if (fread(b, 1, 8 * k, io->f) != 8 * k)
            return -1;
        for (size_t i = 0; i < k; i++) {
            uint64_t x = 0;
            for (int j = 0; j < 8; j++)
                x |= (uint64_t)b[8 * i + (size_t)j] << (8 * j);
            v[i] = x;
        }
        v += k, n -= k;
    }
    return 0;
}

int ppb_mc_tallies_save(const ppb_mc_tallies *t, const char *path, ppb_err *err)
{
    tally_io io = {NULL, ppb_hash64_begin()};
    if (!io.h)
        return ppb_fail(err, "%s: out of memory for the checksum", path);
    ppb_afile af;
    if (ppb_afile_open(&af, path, err)) {
        ppb_hash64_end(io.h);
        return -1;
    }
    io.f = af.f;
    uint64_t head[NHEAD] = {t->fingerprint,
                            t->seed,
                            (uint64_t)t->batches,
                            (uint64_t)t->ncells,
                            t->budget_first,
                            t->budget_photons,
                            t->first,
                            t->count};
    size_t nb = (size_t)t->batches;
    int bad = put_bytes(&io, magic, sizeof magic) || put_u64s(&io, head, NHEAD) ||
              put_u64s(&io, t->photons, nb) || put_u64s(&io, t->totals, nb * PPB_MC_NTOT) ||
              put_u64s(&io, t->cells, nb * PPB_MC_NTALLY * t->ncells);
    uint64_t sum = ppb_hash64_end(io.h);
    unsigned char b[8];
    for (int j = 0; j < 8; j++)
        b[j] = (unsigned char)(sum >> (8 * j));
    bad = bad || fwrite(b, 1, 8, af.f) != 8;
    if (bad) {
        int e = errno;
        ppb_afile_abort(&af);
        return ppb_fail(err, "%s: write failed: %s", path, strerror(e));
    }
    return ppb_afile_commit(&af, err);
}

/* Whether the last 8 bytes of the size-byte file f are the hash of the bytes before them. */
static int checksum_ok(FILE *f, long long size)
{
    ppb_hasher *h = ppb_hash64_begin();
    if (!h)
        return -1;
    unsigned char b[8 * BLOCK];
    long long left = size - 8;
    while (left > 0) {
        size_t k = left < (long long)sizeof b ? (size_t)left : sizeof b;
        if (fread(b, 1, k, f) != k)
            break;
        ppb_hash64_update(h, b, k);
        left -= (long long)k;
    }
    uint64_t sum = ppb_hash64_end(h), stored = 0;
    if (left > 0 || fread(b, 1, 8, f) != 8)
        return 0;
    for (int j = 0; j < 8; j++)
        stored |= (uint64_t)b[j] << (8 * j);
    return stored == sum;
}

int ppb_mc_tallies_load(ppb_mc_tallies *t, const char *path, ppb_err *err)
{
    memset(t, 0, sizeof *t);
    FILE *f = ppb_fopen_regular(path, PPB_READ_MAX, err); /* never a FIFO: open would block */
    if (!f)
        return -1;
    struct stat st;
    char m[8];
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode) ||
        fread(m, 1, sizeof m, f) != sizeof m || memcmp(m, magic, 6) != 0) {
        fclose(f);
        return ppb_fail(err, "%s: not a ppbench Monte Carlo tally file", path);
    }
    if (memcmp(m, magic, sizeof m) != 0) {
        fclose(f);
        return ppb_fail(err,
                        "%s: tally file version %.2s, this ppbench reads %.2s: run the shard again",
                        path, m + 6, magic + 6);
    }
    /* The checksum first, over the whole file: whatever bit is flipped (a header field
     * included), the file is refused as corrupt, never misread. */
    long long size = (long long)st.st_size;
    int ok = size >= (long long)(sizeof magic + 8 * (NHEAD + 1)) && fseek(f, 0, SEEK_SET) == 0
                 ? checksum_ok(f, size)
                 : 0;
    if (ok <= 0) {
        fclose(f);
        return ok < 0 ? ppb_fail(err, "%s: out of memory for the checksum", path)
                      : ppb_fail(err,
                                 "%s: corrupt or truncated tally file (its checksum does not "
                                 "match): copy it again or run the shard again",
                                 path);
    }
    tally_io io = {f, NULL};
    uint64_t head[NHEAD];
    if (fseek(f, (long)sizeof magic, SEEK_SET) != 0 || get_u64s(&io, head, NHEAD)) {
        fclose(f);
        return ppb_fail(err, "%s: cannot read the header", path);
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
    t->budget_first = head[4];
    t->budget_photons = head[5];
    t->first = head[6];
    t->count = head[7];
    size_t nb = (size_t)t->batches;
    double want = 8.0 * ((double)(1 + NHEAD + 1) + (double)nb * (1 + PPB_MC_NTOT) +
                         (double)nb * PPB_MC_NTALLY * (double)t->ncells);
    if ((double)size != want) {
        fclose(f);
        return ppb_fail(err, "%s: %lld bytes, its header implies %.0f: not a tally file", path,
                        size, want);
    }
    if (alloc_arrays(t, err)) {
        fclose(f);
        return -1;
    }
    int bad = get_u64s(&io, t->photons, nb) || get_u64s(&io, t->totals, nb * PPB_MC_NTOT) ||
              get_u64s(&io, t->cells, nb * PPB_MC_NTALLY * t->ncells);
    fclose(f);
    if (bad) {
        ppb_mc_tallies_free(t);
        return ppb_fail(err, "%s: truncated tally file", path);
    }
    return 0;
}

/* Mean and standard error of per-photon quantities whose batch b sums are value(b) (in units
 * of the fixed-point scale): the mean over all photons, and the standard error from the spread
 * of the batch means (batches with no photons are skipped). A series is either one tally per
 * batch (base[b * stride]) or, with surf_mask set, the sum of the once/all-scattered cells of
 * the surfaces in the mask, summed again on each visit: no scratch memory, so the totals cannot
 * fail. The integers are exact, so summing again changes no bit. */
typedef struct batch_stat {
    double mean, se;
} batch_stat;

typedef struct series {
    const uint64_t *base;
    size_t stride;
    const ppb_layout *lo;
    int once, surf_mask;
} series;

static uint64_t series_at(const ppb_mc_tallies *t, const series *sr, size_t b)
{
    if (!sr->surf_mask)
        return sr->base[b * sr->stride];
    const uint64_t *c =
        t->cells + b * (size_t)PPB_MC_NTALLY * t->ncells + (size_t)(sr->once ? 1 : 0) * t->ncells;
    uint64_t sum = 0;
    for (int s = 0; s < sr->lo->nsurf; s++) {
        if (!(sr->surf_mask & (1 << s)))
            continue;
        size_t i0 = ppb_cell(sr->lo, s, 0, 0), i1 = i0 + (size_t)sr->lo->nseg[s] * sr->lo->nbins;
        for (size_t i = i0; i < i1; i++)
            sum += c[i];
    }
    return sum;
}

static batch_stat batch_mean_of(const ppb_mc_tallies *t, const series *sr, double scale)
{
    batch_stat st = {0, 0};
    uint64_t n = 0;
    double sum = 0;
    int used = 0;
    for (int b = 0; b < t->batches; b++) {
        if (!t->photons[b])
            continue;
        sum += (double)series_at(t, sr, (size_t)b);
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
        double mb = (double)series_at(t, sr, (size_t)b) * scale / (double)t->photons[b];
        ss += (mb - st.mean) * (mb - st.mean);
    }
    st.se = sqrt(ss / ((double)used * (double)(used - 1)));
    return st;
}

static batch_stat batch_mean(const ppb_mc_tallies *t, const uint64_t *base, size_t stride,
                             double scale)
{
    series sr = {base, stride, NULL, 0, 0};
    return batch_mean_of(t, &sr, scale);
}

void ppb_mc_tallies_totals(const ppb_mc_tallies *t, const ppb_scene *sc, int once,
                           ppb_mc_totals_stats *st)
{
    memset(st, 0, sizeof *st);
    const double unit = 1.0 / PPB_MC_FIXED_SCALE;
    ppb_layout lo = ppb_scene_layout(sc);
    size_t nb = (size_t)t->batches;
    /* Per-batch sums of each surface (integers, exact), then the batch statistics. */
    series sr1 = {NULL, 0, &lo, once, 1 << PPB_S1}, sr2 = {NULL, 0, &lo, once, 1 << PPB_S2};
    series srs = {NULL, 0, &lo, once, (1 << PPB_S3) | (1 << PPB_S4)};
    batch_stat R = batch_mean_of(t, &sr1, unit);
    batch_stat T = batch_mean_of(t, &sr2, unit);
    batch_stat S = batch_mean_of(t, &srs, unit);
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
    /* The beam's specular reflection at entry is exact, not tallied. */
    st->mean.specular = sc->n > 1.0 ? ppb_fresnel(ppb_scene_cos_theta_l(sc), sc->n) : 0.0;
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

/* mc_totals.csv: one row per (tally, total); mc1's absorbed is not tracked (it is 1 - the rest
 * in totals.csv), so it has no row. */
typedef struct totals_extra {
    ppb_mc_totals_stats st[2]; /* mc, mc1 */
} totals_extra;

static void totals_row(FILE *f, const char *tally, const char *name, double mean, double se)
{
    fprintf(f, "%s,%s,%.10g,%.6g\n", tally, name, mean, se);
}

static int write_totals_extra(const void *data, const char *dir, ppb_err *err)
{
    const totals_extra *x = data;
    ppb_afile af;
    if (ppb_afile_open_csv(&af, dir, "mc_totals.csv", "tally,total,mean,se", err))
        return -1;
    for (int once = 0; once < 2; once++) {
        const ppb_mc_totals_stats *s = &x->st[once];
        const char *id = once ? "mc1" : "mc";
        totals_row(af.f, id, "R", s->mean.R, s->se.R);
        totals_row(af.f, id, "T", s->mean.T, s->se.T);
        totals_row(af.f, id, "sides", s->mean.sides, s->se.sides);
        if (!once)
            totals_row(af.f, id, "absorbed", s->mean.absorbed, s->se.absorbed);
        totals_row(af.f, id, "ballistic", s->mean.ballistic, s->se.ballistic);
    }
    return ppb_afile_commit(&af, err);
}

int ppb_mc_tallies_attach_totals(const ppb_mc_tallies *t, const ppb_scene *sc, ppb_result *mc,
                                 ppb_err *err)
{
    totals_extra *x = malloc(sizeof *x);
    if (!x)
        return ppb_fail(err, "mc: out of memory (mc_totals.csv)");
    ppb_mc_tallies_totals(t, sc, 0, &x->st[0]);
    ppb_mc_tallies_totals(t, sc, 1, &x->st[1]);
    if (mc->extra.data && mc->extra.release)
        mc->extra.release(mc->extra.data);
    mc->extra = (ppb_result_extra){x, write_totals_extra, free};
    return 0;
}
