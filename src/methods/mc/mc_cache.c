#include "methods/mc/mc_cache.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <glob.h>
#include <lzma.h>

#include "base/atomic_file.h"
#include "base/hash.h"
#include "model/config.h"

/* The device and its driver, hashed: "platform / device" and CL_DRIVER_VERSION. */
static int device_hash(ppb_run_ctx *ctx, uint64_t *h, ppb_err *err)
{
    ppb_ocl *ocl;
    if (ppb_ctx_ocl(ctx, &ocl, err))
        return -1;
    char text[1024];
    size_t n = (size_t)snprintf(text, sizeof text, "%s\n", ocl->name);
    if (n < sizeof text && ppb_cl_check(clGetDeviceInfo(ocl->device, CL_DRIVER_VERSION,
                                                        sizeof text - n, text + n, NULL),
                                        "clGetDeviceInfo(CL_DRIVER_VERSION)", err))
        return -1;
    *h = ppb_hash64(text, strlen(text));
    return 0;
}

/* The key's text (mc_cache.h): the canonical line of every key the table marks PPB_MC_KEY,
 * in table order, so a key added to the table joins the key by its flag alone (one added after
 * references were shipped, keyed_when_set, only away from its default, where it changes
 * nothing: [medium] material and channel, so the references of every config without a
 * material keep their keys); the photons per
 * launch when a target noise stops the trace between launches; the kernel's source and the
 * device. */
static int key_text(ppb_run_ctx *ctx, long long chunk, int with_device, FILE *f, ppb_err *err)
{
    const ppb_config *cfg = ctx->cfg;
    uint64_t source, device = 0;
    if (ppb_ocl_source_hash(PPB_MC_KERNEL, &source, err) ||
        (with_device && device_hash(ctx, &device, err)))
        return -1;
    fprintf(f, "ppbench mc reference %d\n", PPB_MC_CACHE_VERSION);
    for (int k = 0; k < ppb_config_nkeys(); k++) {
        ppb_key_info info;
        ppb_config_key_info(k, &info);
        if (info.mc == PPB_MC_KEY) {
            if (!(info.keyed_when_set && ppb_config_key_at_default(cfg, k)))
                ppb_config_write_key(cfg, k, f);
        } else if (info.mc != PPB_NOT_MC_KEY)
            return ppb_fail(err,
                            "mc: key %s.%s: the key table does not say whether it changes "
                            "the Monte Carlo",
                            info.section, info.key);
    }
    if (cfg->mc.target_noise > 0)
        fprintf(f, "photons per launch = %lld\n", chunk);
    fprintf(f, "kernel = %016llx\n", (unsigned long long)source);
    if (with_device)
        fprintf(f, "device = %016llx\n", (unsigned long long)device);
    return 0;
}

/* The key's file name, mc-<key>.bin: with_device 1 for the cache, 0 for the shipped layer. */
static int key_name(ppb_run_ctx *ctx, long long chunk, int with_device, char *buf, size_t cap,
                    ppb_err *err)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return ppb_fail(err, "mc: reference cache: out of memory");
    int status = key_text(ctx, chunk, with_device, f, err);
    if (fclose(f) && status == 0)
        status = ppb_fail(err, "mc: reference cache: out of memory");
    if (status == 0)
        snprintf(buf, cap, "mc-%016llx.bin", (unsigned long long)ppb_hash64(text, len));
    free(text);
    return status;
}

int ppb_mc_cache_path(ppb_run_ctx *ctx, long long chunk, char *buf, size_t cap, ppb_err *err)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return ppb_fail(err, "mc: reference cache: out of memory");
    int status = key_text(ctx, chunk, 1, f, err);
    if (fclose(f) && status == 0)
        status = ppb_fail(err, "mc: reference cache: out of memory");
    if (status == 0)
        snprintf(buf, cap, "%s/mc-%016llx.bin", ctx->ref_cache ? ctx->ref_cache : ".",
                 (unsigned long long)ppb_hash64(text, len));
    free(text);
    return status;
}

#ifndef PPB_SOURCE_DIR
#define PPB_SOURCE_DIR "."
#endif

const char *ppb_mc_shipped_dir(void)
{
    static char buf[PPB_PATH_MAX];
    const char *d = getenv("PPBENCH_REFERENCES");
    if (d && *d)
        return d;
    const char *src = getenv("PPBENCH_SOURCE");
    snprintf(buf, sizeof buf, "%.4000s/references", src && *src ? src : PPB_SOURCE_DIR);
    return buf;
}

/* Decompresses the xz file at path into out: 0, or -1 when it cannot be read or is not whole. */
static int unxz(const char *path, FILE *out)
{
    FILE *in = fopen(path, "rb");
    if (!in)
        return -1;
    lzma_stream z = LZMA_STREAM_INIT;
    if (lzma_stream_decoder(&z, UINT64_MAX, 0) != LZMA_OK) {
        fclose(in);
        return -1;
    }
    static uint8_t ibuf[1 << 16], obuf[1 << 16];
    lzma_ret r = LZMA_OK;
    lzma_action action = LZMA_RUN;
    z.next_out = obuf;
    z.avail_out = sizeof obuf;
    while (r == LZMA_OK) {
        if (z.avail_in == 0 && action == LZMA_RUN) {
            z.next_in = ibuf;
            z.avail_in = fread(ibuf, 1, sizeof ibuf, in);
            if (ferror(in))
                break;
            if (feof(in))
                action = LZMA_FINISH;
        }
        r = lzma_code(&z, action);
        if (z.avail_out == 0 || r == LZMA_STREAM_END) {
            size_t n = sizeof obuf - z.avail_out;
            if (fwrite(obuf, 1, n, out) != n)
                r = LZMA_BUF_ERROR;
            z.next_out = obuf;
            z.avail_out = sizeof obuf;
        }
    }
    lzma_end(&z);
    fclose(in);
    return r == LZMA_STREAM_END ? 0 : -1;
}

/* Loads path (a tally file, or one xz-compressed when xz) into an uninitialised c, and checks
 * its header against the run: 1 when it is this run's reference, 0 when not (said on stderr). */
static int load_checked(ppb_run_ctx *ctx, const char *path, int xz, ppb_mc_tallies *c)
{
    const ppb_config *cfg = ctx->cfg;
    ppb_err err = {{0}};
    char plain[PPB_PATH_MAX + 64];
    snprintf(plain, sizeof plain, "%s", path);
    if (xz) { /* decompressed into a temporary file that mc_tally.c's reader checks as any other */
        const char *tmp = getenv("TMPDIR");
        snprintf(plain, sizeof plain, "%.4000s/ppbench-ref-XXXXXX", tmp && *tmp ? tmp : "/tmp");
        int fd = mkstemp(plain);
        FILE *out = fd < 0 ? NULL : fdopen(fd, "wb");
        int ok = out && unxz(path, out) == 0;
        if (out)
            ok = fclose(out) == 0 && ok;
        else if (fd >= 0)
            close(fd);
        if (!ok) {
            if (fd >= 0)
                unlink(plain);
            fprintf(stderr, "%s: mc: shipped reference %s: cannot be decompressed: not used\n",
                    cfg->name, path);
            return 0;
        }
    }
    int rc = ppb_mc_tallies_load(c, plain, &err);
    if (xz)
        unlink(plain);
    if (rc) {
        if (xz)
            fprintf(stderr, "%s: mc: shipped reference %s: %s: not used\n", cfg->name, path,
                    err.msg);
        else
            fprintf(stderr, "%s: mc: reference cache: %s: not used\n", cfg->name, err.msg);
        return 0;
    }
    int full = cfg->mc.target_noise > 0 || c->count == (uint64_t)cfg->mc.photons;
    if (c->fingerprint != ppb_mc_scene_fingerprint(&cfg->scene) ||
        c->seed != (uint64_t)cfg->mc.seed || c->batches != cfg->mc.batches ||
        c->first != (uint64_t)cfg->mc.first || c->budget_photons != (uint64_t)cfg->mc.photons ||
        !full || !ppb_mc_tallies_range_matches(c)) {
        fprintf(stderr, "%s: mc: reference cache: %s holds another reference: not used\n",
                cfg->name, path);
        ppb_mc_tallies_free(c);
        return 0;
    }
    return 1;
}

/* The shipped layer's file for the key file name `name` (mc-<key>.bin): the first
 * <shipped>/<case>/<name>.xz that exists, in glob order. */
static int shipped_find(const char *name, char *buf, size_t cap)
{
    char pattern[PPB_PATH_MAX + 128];
    snprintf(pattern, sizeof pattern, "%.4000s/*/%.64s.xz", ppb_mc_shipped_dir(), name);
    glob_t g;
    int found = glob(pattern, 0, NULL, &g) == 0 && g.gl_pathc > 0;
    if (found)
        snprintf(buf, cap, "%s", g.gl_pathv[0]);
    globfree(&g);
    return found;
}

void ppb_mc_cache_note_key(ppb_run_ctx *ctx, long long chunk)
{
    ppb_err err = {{0}};
    if (!ctx->ref_cache ||
        key_name(ctx, chunk, 0, ctx->mc_shipped_key, sizeof ctx->mc_shipped_key, &err))
        ctx->mc_shipped_key[0] = '\0';
}

int ppb_mc_cache_get(ppb_run_ctx *ctx, long long chunk, ppb_mc_tallies *t)
{
    const ppb_config *cfg = ctx->cfg;
    char path[PPB_PATH_MAX + 64];
    ppb_err err = {{0}};
    ctx->mc_reference_shipped = 0;
    if (!ctx->ref_cache)
        return 0;
    if (ppb_mc_cache_path(ctx, chunk, path, sizeof path, &err)) {
        fprintf(stderr, "%s: mc: reference cache: %s: not used\n", cfg->name, err.msg);
        return 0;
    }
    ppb_mc_tallies c;
    if (access(path, F_OK) == 0 && load_checked(ctx, path, 0, &c)) {
        snprintf(ctx->mc_reference, sizeof ctx->mc_reference, "%s", path);
        *t = c;
        return 1;
    }
    /* The shipped layer, under the same key but the device's (mc_cache.h): a file there of
     * another key is never looked at. */
    char name[64], ship[PPB_PATH_MAX + 128];
    if (key_name(ctx, chunk, 0, name, sizeof name, &err)) {
        fprintf(stderr, "%s: mc: shipped references: %s: not used\n", cfg->name, err.msg);
        return 0;
    }
    if (shipped_find(name, ship, sizeof ship) && load_checked(ctx, ship, 1, &c)) {
        snprintf(ctx->mc_reference, sizeof ctx->mc_reference, "%.4150s", ship);
        ctx->mc_reference_shipped = 1;
        *t = c;
        return 1;
    }
    return 0;
}

void ppb_mc_cache_put(ppb_run_ctx *ctx, long long chunk, ppb_mc_tallies *t, long long traced)
{
    const ppb_config *cfg = ctx->cfg;
    char path[PPB_PATH_MAX + 64];
    ppb_err err = {{0}};
    if (!ctx->ref_cache)
        return;
    t->budget_first = t->first = (uint64_t)cfg->mc.first;
    t->budget_photons = (uint64_t)cfg->mc.photons;
    t->count = (uint64_t)traced;
    if (ppb_mc_cache_path(ctx, chunk, path, sizeof path, &err) ||
        ppb_mkdirs(ctx->ref_cache, &err) || ppb_mc_tallies_save(t, path, &err))
        fprintf(stderr, "%s: mc: reference cache: not stored: %s\n", cfg->name, err.msg);
    else
        snprintf(ctx->mc_reference, sizeof ctx->mc_reference, "%s", path);
}
