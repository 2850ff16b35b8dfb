/* mc.cl: the photon Monte Carlo transport kernel (SPEC.md sections 1-4 and 7, method `mc`).
 *
 * One work-item traces one photon: it enters S1 uniformly over the lit part along w_L, flies
 * free paths sampled in optical depth through the piecewise-constant medium (traced exactly
 * across the density step plane x = step_x), scatters by Henyey-Greenstein, loses weight by
 * implicit capture (w *= alpha) with unbiased Russian roulette, and leaves at its first boundary
 * crossing (n = 1). Its exit weight goes into integer fixed-point tallies (kernels/mc_params.h),
 * so sums do not depend on the order of the atomic additions.
 *
 * Random numbers: Philox4x32-10 (Random123; Salmon et al., SC'11) keyed by the seed, with the
 * counter (photon index, call number): a photon's path depends only on the seed and its index,
 * never on the work-group size, the chunking or the device layout.
 *
 * Precision: transport in float (positions are O(10) mfp, so float's 1e-6 relative resolution
 * is far below any bin or segment; float halves register pressure and doubles the SIMD width on
 * CPUs). Binning at exit uses the shared double-precision conventions (ppb_conventions.h), the
 * same code the host uses, on the float direction promoted to double. */
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable

#include <Random123/philox.h>

#include "mc_params.h"
#include "ppb_conventions.h"

/* Philox output word to a uniform in (0, 1): 23 bits plus half a step, exact in float, never 0
 * (log) nor 1. Four uniforms per call. */
inline float ppb_mc_uniform(uint r)
{
    return ((float)(r >> 9) + 0.5f) * 0x1p-23f;
}

/* Natural log of x in (0, 1], by the fdlibm/musl logf reduction (x = 2^k (1 + f),
 * log(1 + f) = 2 atanh(f / (2 + f)) by a minimax polynomial in s^2). Written out with plain
 * arithmetic rather than the builtin so that a photon's path does not depend on whether the
 * compiler vectorises the work-item loop (a vector math library may round differently), which
 * would break bit-identity across work-group sizes; it is also faster than PoCL's builtin. */
inline float ppb_mc_log(float x)
{
    int ix = as_int(x) + (0x3f800000 - 0x3f3504f3); /* mantissa into [sqrt(1/2), sqrt(2)) */
    int k = (ix >> 23) - 0x7f;
    float f = as_float((ix & 0x007fffff) + 0x3f3504f3) - 1.0f;
    float s = f / (2.0f + f), z = s * s, w = z * z;
    float t1 = w * (0.40000972152f + w * 0.24279078841f);
    float t2 = z * (0.66666662693f + w * 0.28498786688f);
    float hfsq = 0.5f * f * f, dk = (float)k;
    return s * (hfsq + t1 + t2) + dk * 9.0580006145e-06f - hfsq + f + dk * 6.9313812256e-01f;
}

/* sin and cos of 2 pi u for u in (0, 1): reduction to the nearest quadrant (exact in float),
 * then Taylor polynomials on [-pi/4, pi/4] (truncation below 3e-8). Plain arithmetic, for the
 * reason given at ppb_mc_log. */
inline float ppb_mc_sincos2pi(float u, float *c)
{
    float t = 4.0f * u;
    float q = floor(t + 0.5f);
    float r = (t - q) * 1.57079632679f;
    float r2 = r * r;
    float sr =
        r *
        (1.0f + r2 * (-1.0f / 6 + r2 * (1.0f / 120 + r2 * (-1.0f / 5040 + r2 * (1.0f / 362880)))));
    float cr = 1.0f + r2 * (-0.5f + r2 * (1.0f / 24 + r2 * (-1.0f / 720 + r2 * (1.0f / 40320))));
    switch ((int)q & 3) {
    case 0:
        *c = cr;
        return sr;
    case 1:
        *c = -sr;
        return cr;
    case 2:
        *c = -cr;
        return -sr;
    default:
        *c = sr;
        return -cr;
    }
}

/* A photon's random stream: 32-bit words drawn in order, four per Philox call whose counter is
 * (photon index, call number); the key is the seed. Drawing only the words a step needs (one
 * for the free path, two more for a scattering, one for roulette) costs about one Philox call
 * per 1.3 steps instead of one per step. */
typedef struct ppb_mc_rng {
    philox4x32_key_t key;
    philox4x32_ctr_t ctr;
    philox4x32_ctr_t out;
    int used;
} ppb_mc_rng;

inline ppb_mc_rng ppb_mc_rng_start(ulong seed, ulong photon)
{
    ppb_mc_rng r;
    r.key.v[0] = (uint)seed, r.key.v[1] = (uint)(seed >> 32);
    r.ctr.v[0] = (uint)photon, r.ctr.v[1] = (uint)(photon >> 32);
    r.ctr.v[2] = 0, r.ctr.v[3] = 0;
    r.used = 4;
    return r;
}

inline float ppb_mc_next(ppb_mc_rng *r)
{
    if (r->used == 4) {
        r->out = philox4x32(r->ctr, r->key);
        r->ctr.v[2]++;
        r->used = 0;
    }
    return ppb_mc_uniform(r->out.v[r->used++]);
}

/* Henyey-Greenstein cosine by inversion (e.g. Wang, Jacques & Zheng 1995, MCML Eq. 3.28). */
inline float ppb_mc_hg_cos(float g, float inv_2g, float u)
{
    if (fabs(g) < 1e-4f)
        return 2.0f * u - 1.0f;
    float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
    float c = (1.0f + g * g - s * s) * inv_2g;
    return clamp(c, -1.0f, 1.0f);
}

/* New direction after scattering by polar cosine ct and azimuth (cp, sp) relative to w
 * (MCML Eq. 3.30-3.31 with z as the reference axis; w.z = 0 at entry, so the pole case is
 * rare). One Newton step for 1/|n| around 1 renormalises it, so float round-off cannot build
 * up along long paths. */
inline float3 ppb_mc_rotate(float3 w, float ct, float cp, float sp)
{
    float st = sqrt(fmax(0.0f, 1.0f - ct * ct));
    float3 n;
    if (fabs(w.z) > 0.99999f) {
        n = (float3)(st * cp, st * sp, copysign(ct, w.z));
    } else {
        float r2 = 1.0f - w.z * w.z;
        float r = sqrt(r2), st_r = st / r;
        n.x = st_r * (w.x * w.z * cp - w.y * sp) + w.x * ct;
        n.y = st_r * (w.y * w.z * cp + w.x * sp) + w.y * ct;
        n.z = -st * cp * r + w.z * ct;
    }
    return n * (1.5f - 0.5f * dot(n, n));
}

/* Segment of an exit point on surface surf (slab: always 0). */
inline int ppb_mc_segment(const ppb_mc_params *p, int surf, float x, float y)
{
    if (!p->tube)
        return 0;
    if (surf == PPB_S1 || surf == PPB_S2)
        return ppb_segment_of((double)x, -0.5 * (double)p->width, (double)p->width, p->nseg[surf]);
    return ppb_segment_of((double)y, -(double)p->height, (double)p->height, p->nseg[surf]);
}

/* Fixed-point weight (kernels/mc_params.h). */
inline ulong ppb_mc_fixed(float w)
{
    return convert_ulong_rte(w * PPB_MC_FIXED_SCALE);
}

/* Per-work-item sums of the totals: integers, added to the batch's totals once at the end. */
typedef struct ppb_mc_sums {
    ulong ballistic, capture, rgain, rloss, events;
} ppb_mc_sums;

/* Traces one photon and tallies its exit. */
inline void ppb_mc_photon(const ppb_mc_params *pp, ulong photon, __global ulong *base,
                          ppb_mc_sums *sums)
{
    const ppb_mc_params p = *pp;
    ppb_mc_rng rng = ppb_mc_rng_start(p.seed, photon);
    /* Entry on S1 (y = 0) along w_L. */
    float x = 0.0f, y = 0.0f;
    if (p.tube)
        x = p.enter_x0 + p.enter_width * ppb_mc_next(&rng);
    float3 w = (float3)(p.light_x, p.light_y, 0.0f);
    const float half_w = 0.5f * p.width;
    const int density_step = p.step == PPB_STEP_DENSITY;
    const float inv_2g = 0.5f / p.g; /* unused (inf) when g = 0 */
    const float inv_sigma_left = 1.0f / p.sigma_t, inv_sigma_right = 1.0f / p.sigma_t_right;

    float weight = 1.0f, capture = 0.0f, rgain = 0.0f, rloss = 0.0f;
    uint nscat = 0;
    int exit_surf = -1;

    for (;;) {
        float tau = -ppb_mc_log(ppb_mc_next(&rng)); /* optical depth to the next interaction */

        /* Fly: at most two legs, since a straight line crosses the step plane at most once.
         * A point on the plane belongs to the side it moves into (x >= step_x is right). */
        for (;;) {
            float dx = INFINITY, dy = INFINITY;
            if (p.tube) {
                if (w.x > 0.0f)
                    dx = (half_w - x) / w.x;
                else if (w.x < 0.0f)
                    dx = (-half_w - x) / w.x;
            }
            if (w.y > 0.0f)
                dy = -y / w.y;
            else if (w.y < 0.0f)
                dy = (-p.height - y) / w.y;
            float d_wall = fmin(dx, dy);

            float sigma = p.sigma_t, inv_sigma = inv_sigma_left, d_plane = INFINITY;
            if (density_step) {
                int right = x > p.step_x || (x == p.step_x && w.x >= 0.0f);
                sigma = right ? p.sigma_t_right : p.sigma_t;
                inv_sigma = right ? inv_sigma_right : inv_sigma_left;
                if (right && w.x < 0.0f)
                    d_plane = (p.step_x - x) / w.x;
                else if (!right && w.x > 0.0f)
                    d_plane = (p.step_x - x) / w.x;
            }
            float d_leg = fmin(d_wall, d_plane);
            float s = tau * inv_sigma;
            if (s < d_leg) {
                x += s * w.x;
                y += s * w.y;
                break; /* interaction inside the medium */
            }
            tau = fmax(0.0f, tau - d_leg * sigma);
            if (d_plane < d_wall) {
                y += d_plane * w.y;
                x = p.step_x; /* exactly on the plane: the side test above sees the crossing */
                continue;
            }
            if (dx <= dy) {
                exit_surf = w.x > 0.0f ? PPB_S4 : PPB_S3;
                y += dx * w.y;
                x = w.x > 0.0f ? half_w : -half_w;
            } else {
                exit_surf = w.y > 0.0f ? PPB_S1 : PPB_S2;
                x += dy * w.x;
                y = w.y > 0.0f ? 0.0f : -p.height;
            }
            break;
        }
        if (exit_surf >= 0)
            break;

        /* Scatter: implicit capture with the albedo at the interaction point. */
        float alpha = (float)ppb_albedo_at((double)x, p.step, (double)p.step_x, (double)p.albedo,
                                           (double)p.albedo_right);
        capture += weight * (1.0f - alpha);
        weight *= alpha;
        nscat++;
        if (weight <= 0.0f)
            break; /* alpha = 0: captured whole */
        float ct = ppb_mc_hg_cos(p.g, inv_2g, ppb_mc_next(&rng));
        float cp, sp = ppb_mc_sincos2pi(ppb_mc_next(&rng), &cp);
        w = ppb_mc_rotate(w, ct, cp, sp);

        /* Russian roulette: survive with probability 1/M at M times the weight (M = 8, so
         * the test u < 1/M on the 2^-23 grid has probability exactly 1/M). */
        if (weight < PPB_MC_ROULETTE_W) {
            if (ppb_mc_next(&rng) < 1.0f / PPB_MC_ROULETTE_M) {
                rgain += weight * (PPB_MC_ROULETTE_M - 1.0f);
                weight *= PPB_MC_ROULETTE_M;
            } else {
                rloss += weight;
                weight = 0.0f;
                break;
            }
        }
    }

    if (exit_surf >= 0) {
        ulong q = ppb_mc_fixed(weight);
        if (nscat == 0) {
            sums->ballistic += q;
        } else {
            int seg = ppb_mc_segment(&p, exit_surf, x, y);
            int bin =
                ppb_dir_bin(exit_surf, (double)w.x, (double)w.y, (double)w.z, p.ntheta, p.nphi);
            size_t cell =
                ((size_t)p.offset[exit_surf] + (size_t)seg) * (size_t)(p.ntheta * p.nphi) +
                (size_t)bin;
            atom_add(base + PPB_MC_TALLY_ALL * p.ncells + cell, q);
            if (nscat == 1)
                atom_add(base + PPB_MC_TALLY_ONCE * p.ncells + cell, q);
        }
    }
    sums->capture += ppb_mc_fixed(capture);
    sums->events += nscat;
    sums->rgain += ppb_mc_fixed(rgain);
    sums->rloss += ppb_mc_fixed(rloss);
}

/* The global size is batches x P (the host makes it so): work-items [b P, (b + 1) P) trace the
 * chunk's photons of batch b (i % batches == b), work-item b P + q taking the q-th, (q + P)-th,
 * ... of them. Work-groups of consecutive work-items then stay inside one batch, so the cell
 * tallies they update are one batch's slice (cache-resident on a CPU), and a work-item's
 * totals are summed privately with one atomic per total at the end. Which work-item traces a
 * photon never changes the photon's path, and integer sums do not depend on their order, so any
 * global size, work-group size or chunking gives the same tallies. */
__kernel void ppb_mc_trace_kernel(const ppb_mc_params p, __global ulong *cells,
                                  __global ulong *totals)
{
    const ulong per_batch = get_global_size(0) / (ulong)p.batches;
    const ulong batches = (ulong)p.batches;
    const int batch = (int)(get_global_id(0) / per_batch);
    const ulong q0 = get_global_id(0) % per_batch;
    /* The chunk's photons of this batch: first + off + batches m, m = 0 .. n - 1. */
    const ulong off = ((ulong)batch + batches - p.first % batches) % batches;
    const ulong n = off < p.count ? (p.count - off - 1) / batches + 1 : 0;
    if (q0 >= n)
        return;
    __global ulong *base = cells + (size_t)batch * PPB_MC_NTALLY * p.ncells;
    ppb_mc_sums sums = {0, 0, 0, 0, 0};
    for (ulong m = q0; m < n; m += per_batch)
        ppb_mc_photon(&p, p.first + off + batches * m, base, &sums);

    __global ulong *tot = totals + (size_t)batch * PPB_MC_NTOT;
    atom_add(tot + PPB_MC_T_BALLISTIC, sums.ballistic);
    atom_add(tot + PPB_MC_T_CAPTURE, sums.capture);
    atom_add(tot + PPB_MC_T_EVENTS, sums.events);
    atom_add(tot + PPB_MC_T_RGAIN, sums.rgain);
    atom_add(tot + PPB_MC_T_RLOSS, sums.rloss);
}
