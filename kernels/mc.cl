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
 * counter (photon index, step, stream): a photon's path depends only on the seed and its index,
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

/* Counter of a photon's random draws: stream 0 is the entry point, stream 1 the steps. */
inline philox4x32_ctr_t ppb_mc_counter(ulong photon, uint step, uint stream)
{
    philox4x32_ctr_t c = {{(uint)photon, (uint)(photon >> 32), step, stream}};
    return c;
}

/* Henyey-Greenstein cosine by inversion (e.g. Wang, Jacques & Zheng 1995, MCML Eq. 3.28). */
inline float ppb_mc_hg_cos(float g, float u)
{
    if (fabs(g) < 1e-4f)
        return 2.0f * u - 1.0f;
    float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
    float c = (1.0f + g * g - s * s) / (2.0f * g);
    return clamp(c, -1.0f, 1.0f);
}

/* New direction after scattering by polar cosine ct and azimuth (cp, sp) relative to w
 * (MCML Eq. 3.30-3.31 with z as the reference axis; w.z = 0 at entry, so the pole case is
 * rare). Renormalised so float round-off cannot build up along long paths. */
inline float3 ppb_mc_rotate(float3 w, float ct, float cp, float sp)
{
    float st = sqrt(fmax(0.0f, 1.0f - ct * ct));
    float3 n;
    if (fabs(w.z) > 0.99999f) {
        n = (float3)(st * cp, st * sp, copysign(ct, w.z));
    } else {
        float r = sqrt(1.0f - w.z * w.z);
        n.x = st * (w.x * w.z * cp - w.y * sp) / r + w.x * ct;
        n.y = st * (w.y * w.z * cp + w.x * sp) / r + w.y * ct;
        n.z = -st * cp * r + w.z * ct;
    }
    return n * rsqrt(dot(n, n));
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

__kernel void ppb_mc_trace_kernel(const ppb_mc_params p, __global ulong *cells,
                                  __global ulong *totals)
{
    ulong k = get_global_id(0);
    if (k >= p.count)
        return;
    const ulong photon = p.first + k;
    const int batch = (int)(photon % (ulong)p.batches);
    philox4x32_key_t key = {{(uint)p.seed, (uint)(p.seed >> 32)}};

    /* Entry on S1 (y = 0) along w_L. */
    float x = 0.0f, y = 0.0f;
    if (p.tube) {
        philox4x32_ctr_t r = philox4x32(ppb_mc_counter(photon, 0, 0), key);
        x = p.enter_x0 + p.enter_width * ppb_mc_uniform(r.v[0]);
    }
    float3 w = (float3)(p.light_x, p.light_y, 0.0f);
    const float half_w = 0.5f * p.width;
    const int density_step = p.step == PPB_STEP_DENSITY;

    float weight = 1.0f, capture = 0.0f, rgain = 0.0f, rloss = 0.0f;
    uint nscat = 0;
    int exit_surf = -1;

    for (uint step = 0;; step++) {
        philox4x32_ctr_t r = philox4x32(ppb_mc_counter(photon, step, 1), key);
        float tau = -log(ppb_mc_uniform(r.v[0])); /* optical depth to the next interaction */

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

            float sigma = p.sigma_t, d_plane = INFINITY;
            if (density_step) {
                int right = x > p.step_x || (x == p.step_x && w.x >= 0.0f);
                sigma = right ? p.sigma_t_right : p.sigma_t;
                if (right && w.x < 0.0f)
                    d_plane = (p.step_x - x) / w.x;
                else if (!right && w.x > 0.0f)
                    d_plane = (p.step_x - x) / w.x;
            }
            float d_leg = fmin(d_wall, d_plane);
            float s = tau / sigma;
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
            break;
        float ct = ppb_mc_hg_cos(p.g, ppb_mc_uniform(r.v[1]));
        float cp, sp = sincos(2.0f * M_PI_F * ppb_mc_uniform(r.v[2]), &cp);
        w = ppb_mc_rotate(w, ct, cp, sp);

        /* Russian roulette: survive with probability 1/M at M times the weight (M = 8, so
         * the test u < 1/M on the 2^-23 grid has probability exactly 1/M). */
        if (weight < PPB_MC_ROULETTE_W) {
            if (ppb_mc_uniform(r.v[3]) < 1.0f / PPB_MC_ROULETTE_M) {
                rgain += weight * (PPB_MC_ROULETTE_M - 1.0f);
                weight *= PPB_MC_ROULETTE_M;
            } else {
                rloss += weight;
                weight = 0.0f;
                break;
            }
        }
    }

    __global ulong *tot = totals + (size_t)batch * PPB_MC_NTOT;
    if (exit_surf >= 0) {
        ulong q = ppb_mc_fixed(weight);
        if (nscat == 0) {
            atom_add(tot + PPB_MC_T_BALLISTIC, q);
        } else {
            int seg = ppb_mc_segment(&p, exit_surf, x, y);
            int bin =
                ppb_dir_bin(exit_surf, (double)w.x, (double)w.y, (double)w.z, p.ntheta, p.nphi);
            size_t cell =
                ((size_t)p.offset[exit_surf] + (size_t)seg) * (size_t)(p.ntheta * p.nphi) +
                (size_t)bin;
            __global ulong *base = cells + (size_t)batch * PPB_MC_NTALLY * p.ncells;
            atom_add(base + PPB_MC_TALLY_ALL * p.ncells + cell, q);
            if (nscat == 1)
                atom_add(base + PPB_MC_TALLY_ONCE * p.ncells + cell, q);
        }
    }
    if (nscat > 0) {
        atom_add(tot + PPB_MC_T_CAPTURE, ppb_mc_fixed(capture));
        atom_add(tot + PPB_MC_T_EVENTS, (ulong)nscat);
    }
    if (rgain > 0.0f)
        atom_add(tot + PPB_MC_T_RGAIN, ppb_mc_fixed(rgain));
    if (rloss > 0.0f)
        atom_add(tot + PPB_MC_T_RLOSS, ppb_mc_fixed(rloss));
}
