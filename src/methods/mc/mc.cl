/* mc.cl: the photon Monte Carlo transport kernel (reference: Medium to Bins, Methods; `mc`).
 *
 * A photon enters S1 uniformly over the lit part along w_L, flies free paths sampled in optical
 * depth through the piecewise-constant medium (traced exactly across the density step plane
 * x = step_x), scatters by Henyey-Greenstein, loses weight by implicit capture (w *= alpha) with
 * unbiased Russian roulette (applied at every event past an event cap, kernels/mc_params.h, so
 * no photon can run forever), and leaves at its first boundary crossing when n = 1. At n > 1
 * it enters refracted with weight 1 - F(theta_L) and at every boundary hit is
 * reflected specularly with probability F(cos theta_i) or leaves refracted into air, the exit
 * binned by its air-side direction (ppb_mc_boundaries). Its exit weight goes into integer
 * fixed-point tallies (kernels/mc_params.h), so sums do not depend on the order of the atomic
 * additions.
 *
 * Layout: each work-item runs PPB_MC_LANES photons side by side in OpenCL vector types (one
 * photon per lane; a lane whose photon leaves or dies waits, and once PPB_MC_REFILL lanes wait
 * they are tallied and take the work-item's next photons together). On a CPU this is what
 * makes the kernel SIMD: a photon's loop has a data-dependent trip count, so no compiler
 * vectorises across work-items. The host picks the CPU's native float vector width (16 with
 * AVX-512, 8 with AVX2) and 2 on GPUs; a photon's path never depends on its lane, work-item or
 * launch.
 *
 * Random numbers: Philox4x32-10 (Random123; Salmon et al., SC'11, the same bijection as
 * Random123's philox4x32, evaluated on a vector of counters) keyed by the seed. Photon i's
 * k-th step uses the counter (i mod 2^32, i / 2^32, k, 0): free path, HG cosine, azimuth,
 * roulette; its entry point uses (i mod 2^32, i / 2^32, 0, 1). A step that ends at a wall uses
 * none of the last three words, so at n > 1 the reflect-or-leave choice takes the fourth (the
 * roulette's, which only an interaction uses). So a photon's path depends only on the seed and
 * its index.
 *
 * Precision: transport in float (positions are O(10) mfp, so float's 1e-7 relative resolution
 * is far below any bin or segment; float doubles the SIMD width over double). Exits are binned
 * as the shared double-precision conventions (ppb_conventions.h) bin the float direction
 * promoted to double, the same code the host uses: in float vectors where float decides the
 * same bin, in that double code where it may not (ppb_mc_vbins). log and sin/cos are written out in
 * plain arithmetic (below) so that results cannot depend on which math-library variant a compiler
 * picks for a vector width. */
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable

#include <Random123/philox.h>

#include "mc_params.h"
#include "ppb_conventions.h"
#include "ppb_fresnel.h"
#include "ppb_tube.h"

#ifndef PPB_MC_LANES
#define PPB_MC_LANES 8
#endif
#define PPB_CAT_(a, b) a##b
#define PPB_CAT(a, b)  PPB_CAT_(a, b)
#define PPB_VEC(type)  PPB_CAT(type, PPB_MC_LANES)
typedef PPB_VEC(float) vfloat;
typedef PPB_VEC(int) vint; /* lane masks: -1 true, 0 false, as vector comparisons give */
typedef PPB_VEC(uint) vuint;
#define VLOAD          PPB_CAT(vload, PPB_MC_LANES)
#define VSTORE         PPB_CAT(vstore, PPB_MC_LANES)
#define AS_VINT        PPB_CAT(as_int, PPB_MC_LANES)
#define AS_VUINT       PPB_CAT(as_uint, PPB_MC_LANES)
#define AS_VFLOAT      PPB_CAT(as_float, PPB_MC_LANES)
#define CONVERT_VFLOAT PPB_CAT(convert_float, PPB_MC_LANES)
#define CONVERT_VINT   PPB_CAT(convert_int, PPB_MC_LANES)
#define CONVERT_VUINT  PPB_CAT(convert_uint, PPB_MC_LANES)
#define CONVERT_VULONG PPB_CAT(convert_ulong, PPB_MC_LANES)
typedef PPB_VEC(ulong) vulong;
typedef PPB_VEC(long) vlong; /* masks for vulong selects */
typedef PPB_VEC(double) vdouble;
#define CONVERT_VLONG   PPB_CAT(convert_long, PPB_MC_LANES)
#define CONVERT_VDOUBLE PPB_CAT(convert_double, PPB_MC_LANES)
#define AS_VULONG       PPB_CAT(as_ulong, PPB_MC_LANES)
#define LANES           PPB_MC_LANES
/* PoCL compiles `inline` away (-Dinline=); the per-step functions are inlined by force so the
 * lane vectors need not pass through memory between them. */
#define PPB_MC_HOT inline __attribute__((always_inline))

/* Uniforms and the scattering samplers (tests/test_mc.c runs them alone). */
#include "ppb_sampling.h"

/* Philox4x32-10 of PPB_MC_LANES counters (Random123's round and key schedule). */
typedef struct ppb_mc_vctr {
    vuint v0, v1, v2, v3;
} ppb_mc_vctr;

/* Each 32-bit word rides in the low half of a 64-bit lane, so that a round is two 32 x 32 ->
 * 64-bit multiplies (vpmuludq, which reads only the low halves), two shifts for the high words
 * and the XORs, with nothing repacked into 32-bit lanes (repacking the products'
 * halves, vpmulld for the low words and two permutes for the high ones, made a round half
 * again as long; PoCL's vector mul_hi, in 16-bit pieces, was worse still). The high halves
 * carry garbage that no low half ever sees: XOR is bitwise and the multiplies read the low
 * halves only. Unrolled, the round keys k + r W are constants of the launch. The same words as
 * Random123's philox4x32 (tests/test_mc.c checks them). */
PPB_MC_HOT ppb_mc_vctr ppb_mc_philox(ppb_mc_vctr c, uint k0, uint k1)
{
    const vulong low = (vulong)0xffffffffUL;
    vulong a0 = CONVERT_VULONG(c.v0), a1 = CONVERT_VULONG(c.v1);
    vulong a2 = CONVERT_VULONG(c.v2), a3 = CONVERT_VULONG(c.v3);
#pragma unroll
    for (int round = 0; round < 10; round++) {
        vulong p0 = (a0 & low) * (ulong)PHILOX_M4x32_0;
        vulong p1 = (a2 & low) * (ulong)PHILOX_M4x32_1;
        a0 = (p1 >> 32) ^ a1 ^ (ulong)k0;
        a2 = (p0 >> 32) ^ a3 ^ (ulong)k1;
        a1 = p1, a3 = p0;
        k0 += PHILOX_W32_0, k1 += PHILOX_W32_1;
    }
    ppb_mc_vctr out = {CONVERT_VUINT(a0), CONVERT_VUINT(a1), CONVERT_VUINT(a2), CONVERT_VUINT(a3)};
    return out;
}

/* Natural log of x in (0, 1], by the fdlibm/musl logf reduction (x = 2^k (1 + f),
 * log(1 + f) = 2 atanh(f / (2 + f)) by a minimax polynomial in s^2); relative error below
 * 1e-7 over the uniforms drawn here. */
PPB_MC_HOT vfloat ppb_mc_log(vfloat x)
{
    vint ix = AS_VINT(x) + (0x3f800000 - 0x3f3504f3); /* mantissa into [sqrt(1/2), sqrt(2)) */
    vfloat k = CONVERT_VFLOAT((ix >> 23) - 0x7f);
    vfloat f = AS_VFLOAT((ix & 0x007fffff) + 0x3f3504f3) - 1.0f;
    vfloat s = f / (2.0f + f), z = s * s, w = z * z;
    vfloat t1 = w * (0.40000972152f + w * 0.24279078841f);
    vfloat t2 = z * (0.66666662693f + w * 0.28498786688f);
    vfloat hfsq = 0.5f * f * f;
    return s * (hfsq + t1 + t2) + k * 9.0580006145e-06f - hfsq + f + k * 6.9313812256e-01f;
}

/* Segment of an exit point on surface surf (slab: always 0). */
inline int ppb_mc_segment(const ppb_mc_params *p, int surf, float x, float y)
{
    if (!p->med.tube)
        return 0;
    /* the float tube's (mc_params.h) */
    double w = (double)(float)p->med.width, h = (double)(float)p->med.height;
    return ppb_segment_at(surf, ppb_face_is_side(surf) ? (double)y : (double)x, p->nseg[surf], w,
                          h);
}

/* The phi-bin edges e_k = k pi / nphi, k = 1 .. nphi - 1, as (cos e_k, sin e_k): computed once
 * per work-item so that binning an exit needs no atan2 (atan2 was a fifth of the
 * kernel's time). */
typedef struct ppb_mc_edges {
    double c[PPB_MC_MAX_PHI], s[PPB_MC_MAX_PHI];
    float cf[PPB_MC_MAX_PHI], sf[PPB_MC_MAX_PHI]; /* the same rounded to float (ppb_mc_vbins) */
} ppb_mc_edges;

inline void ppb_mc_edges_init(const ppb_mc_params *p, ppb_mc_edges *e)
{
    for (int k = 1; k < p->nphi && k < PPB_MC_MAX_PHI; k++) {
        double a = (double)k * (PPB_PI / (double)p->nphi);
        e->c[k] = cos(a), e->s[k] = sin(a);
        e->cf[k] = (float)e->c[k], e->sf[k] = (float)e->s[k];
    }
}

/* ppb_phi_bin (ppb_conventions.h) without atan2, the same bin bit for bit. For b = |w.b| >= 0
 * the direction's angle phi = atan2(b, t) lies in [0, pi], and so does every edge, so
 * c_k = b cos e_k - t sin e_k = r sin(phi - e_k) is positive exactly where phi > e_k and
 * falls with k: the bin is the number of edges with c_k > 0, found by bisection. t and b are
 * floats promoted to double (|t|, |b| <= 1), so c_k is within 1e-15 of its exact value, and
 * ppb_phi_bin's own edge (where phi / pi nphi, with atan2's ulp error, crosses k) is within
 * 1e-14 rad of e_k; wherever some tested |c_k| <= 1e-12 the direction is too close to an edge
 * to decide so, and ppb_phi_bin itself decides (a probability of order 1e-11 per exit). */
inline int ppb_mc_phi_bin(const ppb_mc_edges *e, double t, double b, int nphi)
{
    if (nphi > PPB_MC_MAX_PHI)
        return ppb_phi_bin(t, b, nphi);
    int lo = 0, hi = nphi - 1; /* the bin lies in [lo, hi] */
    while (lo < hi) {
        int k = (lo + hi + 1) / 2; /* edge k separates bins k - 1 and k */
        double c = b * e->c[k] - t * e->s[k];
        if (fabs(c) <= 1e-12)
            return ppb_phi_bin(t, b, nphi);
        int up = c > 0.0; /* selects, not branches: the side is a coin toss per exit */
        lo = up ? k : lo;
        hi = up ? hi : k - 1;
    }
    return lo;
}

/* ppb_dir_bin (ppb_conventions.h) with the phi bin above: the same bin. */
inline int ppb_mc_dir_bin(const ppb_mc_params *p, const ppb_mc_edges *e, int surf, double wx,
                          double wy, double wz)
{
    double mu = wx * ppb_normal_x(surf) + wy * ppb_normal_y(surf);
    double wt = wx * ppb_tangent_x(surf) + wy * ppb_tangent_y(surf);
    return ppb_bin_index(ppb_theta_bin(mu, p->ntheta), ppb_mc_phi_bin(e, wt, fabs(wz), p->nphi),
                         p->nphi);
}

/* Fixed-point weights (kernels/mc_params.h) of every lane, round(w 2^32) half to even, as
 * convert_ulong_rte would give, without PoCL's generic float -> ulong conversion nor a scalar
 * double -> long one per lane (x86 has no vector form below AVX-512): w * 2^32 is exact in
 * float (a power-of-two scale) and in double, below 2^45 (weights are >= 0 and at most
 * 8 PPB_MC_CAP_WMAX); adding 2^52 rounds it to the integer grid of [2^52, 2^53) half to even,
 * leaving the integer in the low mantissa bits. */
PPB_MC_HOT vulong ppb_mc_vfixed(vfloat w)
{
    vdouble d = CONVERT_VDOUBLE(w * PPB_MC_FIXED_SCALE) + 0x1p52;
    return AS_VULONG(d) - (vulong)0x4330000000000000UL; /* the bits of 2^52 */
}

/* Per-work-item sums of the totals, lane by lane: integers, so their order does not matter;
 * added to the batch's totals once at the end. */
typedef struct ppb_mc_sums {
    vulong ballistic, capture, rgain, rloss, events, capped;
} ppb_mc_sums;

/* Sum of a vulong's lanes (by pointer: a 512-bit vector argument draws PoCL's ABI warning). */
inline ulong ppb_mc_hsum(const vulong *v)
{
    ulong a[LANES], sum = 0;
    VSTORE(*v, 0, a);
    for (int l = 0; l < LANES; l++)
        sum += a[l];
    return sum;
}

/* Cell-tally additions waiting to be made, flushed PPB_MC_PEND at a time (the lock
 * add of each exit, made at once, was a sixth of the kernel's time, stalled behind the step's
 * pending stores and the cell's cache miss). Each cell is prefetched when its addition is
 * queued (ppb_mc_tally), so that its miss overlaps the steps until the flush (a load there
 * would hold up retirement until the line came); a flush first reads every pending cell, so
 * the misses left overlap, then adds. Integer sums do not depend on the order of the
 * additions. */
#define PPB_MC_PEND 32
/* A tally cell's line, for writing: clang's builtin on CPUs (the host sets
 * PPB_MC_CPU_PREFETCH), as OpenCL's prefetch() is an empty function in PoCL's kernel library;
 * OpenCL's own elsewhere. */
#if PPB_MC_CPU_PREFETCH
#define PPB_MC_PREFETCH(ptr) __builtin_prefetch((ptr), 1, 3)
#else
#define PPB_MC_PREFETCH(ptr) prefetch((ptr), 1)
#endif
typedef struct ppb_mc_pending {
    size_t cell[PPB_MC_PEND];
    ulong q[PPB_MC_PEND];
    int n;
} ppb_mc_pending;

inline void ppb_mc_flush(ppb_mc_pending *pend, __global ulong *base, __global ulong *spare)
{
    ulong touch = 0;
    for (int i = 0; i < pend->n; i++)
        touch += base[pend->cell[i]];
    for (int i = 0; i < pend->n; i++)
        atom_add(base + pend->cell[i], pend->q[i]);
    pend->n = 0;
    /* Keeps the reads above (their sum is otherwise unused); adding 0 changes nothing. */
    if (touch == 0x9e3779b97f4a7c15UL)
        atom_add(spare, 0UL);
}

/* The lanes' indices, for lane bits (ppb_mc_bits) and ranks (ppb_mc_refill). */
#if LANES == 2
#define PPB_MC_IOTA ((vuint)(0, 1))
#elif LANES == 4
#define PPB_MC_IOTA ((vuint)(0, 1, 2, 3))
#elif LANES == 8
#define PPB_MC_IOTA ((vuint)(0, 1, 2, 3, 4, 5, 6, 7))
#elif LANES == 16
#define PPB_MC_IOTA ((vuint)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15))
#else
#error "PPB_MC_LANES must be 2, 4, 8 or 16"
#endif

/* The true lanes of a mask as the bits of an integer, bit l for lane l, by an OR over halves:
 * PoCL's any() tests lane after lane, a branch each. */
PPB_MC_HOT uint ppb_mc_bits(vint mask)
{
    vuint b = AS_VUINT(mask) & ((vuint)1 << PPB_MC_IOTA);
#if LANES == 16
    uint8 b8 = b.lo | b.hi;
    uint4 b4 = b8.lo | b8.hi;
    uint2 b2 = b4.lo | b4.hi;
#elif LANES == 8
    uint4 b4 = b.lo | b.hi;
    uint2 b2 = b4.lo | b4.hi;
#elif LANES == 4
    uint2 b2 = b.lo | b.hi;
#else
    uint2 b2 = b;
#endif
    return b2.x | b2.y;
}

/* The lowest lane of a nonzero set of lane bits (ctz is OpenCL 2.0). */
inline int ppb_mc_low_lane(uint bits)
{
    return 31 - (int)clz(bits & (0u - bits));
}

/* The state of every lane as vectors, which stay in registers from step to step (kept
 * in private arrays, it was loaded and stored whole every step and written lane by lane
 * at every photon's start, and the vector loads that followed those scalar stores stalled). A
 * lane whose photon has finished keeps its final state (done; masked out of every update) until
 * ppb_mc_refill tallies and replaces it, together with the other finished lanes. */
typedef struct ppb_mc_state {
    vfloat x, y, wx, wy, wz, weight, tau;
    vfloat capture, rgain, rloss; /* weight removed by capture, won and lost by roulette */
    vuint ctr0, ctr1, step;       /* the Philox counter: photon index (two words), step */
    vint nscat, capped;           /* scatterings; roulettes forced by the event cap */
    vint need_tau;                /* the next leg draws a new optical depth */
    vint active;                  /* the lane flies a photon */
    vint done, left, side;        /* finished; by leaving (else it died); through a side wall */
} ppb_mc_state;

/* The work-item's photons in order: the m-th is first + off + batches m, m = q0, q0 + P, ...
 * (n: the end), with the entry words (Philox word 0 of the counter (i mod 2^32, i / 2^32, 0, 1),
 * for photon i) of the next ones made LANES at a time: word[used + j] is the photon m + j P's. */
typedef struct ppb_mc_queue {
    ulong m, n, step, base, stride; /* next m, end, P, first + off, batches */
    uint word[2 * LANES];
    int used;
} ppb_mc_queue;

/* The entry words of the photons m0 + j P, j = 0 .. LANES - 1, into w, by one vector Philox
 * (a scalar one per photon was a tenth of the kernel's time, one on all lanes at
 * every refill 7%). */
PPB_MC_HOT void ppb_mc_entry_words(const ppb_mc_params *p, const ppb_mc_queue *q, ulong m0, uint *w)
{
    vulong photon =
        (vulong)q->base + (vulong)q->stride * ((vulong)m0 + CONVERT_VULONG(PPB_MC_IOTA) * q->step);
    ppb_mc_vctr c = {CONVERT_VUINT(photon), CONVERT_VUINT(photon >> 32), (vuint)0, (vuint)1};
    c = ppb_mc_philox(c, (uint)p->seed, (uint)(p->seed >> 32));
    VSTORE(c.v0, 0, w);
}

/* The entry points on S1 of the queue's next photons for the lanes of bits, in lane order (the
 * k-th lane of bits takes word used + k), as a vector (other lanes 0); the words used are
 * dropped and the next LANES made once fewer than LANES are left. */
PPB_MC_HOT vfloat ppb_mc_entry_x(const ppb_mc_params *p, ppb_mc_queue *q, uint bits)
{
    int count = popcount(bits);
    if (q->used + count >= LANES)
        ppb_mc_entry_words(p, q, q->m + (ulong)(LANES - q->used) * q->step, q->word + LANES);
    vfloat x = (vfloat)0.0f;
    int k = q->used;
    for (uint b = bits; b; b &= b - 1) {
        float xl = p->enter_x0 + p->enter_width * ppb_mc_uniform1(q->word[k++]);
        x = select(x, (vfloat)xl, PPB_MC_IOTA == (vuint)ppb_mc_low_lane(b));
    }
    q->used += count;
    if (q->used >= LANES) {
        q->used -= LANES;
        for (int j = 0; j < LANES; j++)
            q->word[j] = q->word[j + LANES];
    }
    return x;
}

/* Refill finished lanes only once this many have finished (or none flies): a photon takes
 * about six steps, so with 8 lanes some lane finishes on three steps in four, and a refill (the
 * tallies, exit bins and ranks, all on every lane) then ran almost every step;
 * waiting for a quarter of the lanes idles a few lanes for a step or two instead. Which lane
 * traces a photon never changes its path. */
#ifndef PPB_MC_REFILL
#define PPB_MC_REFILL (LANES >= 8 ? LANES / 4 : 1)
#endif

/* Restarts every finished lane (bits: s->done as lane bits) with the queue's next photons, in
 * lane order (a lane's rank: the finished lanes below it), or idles it when the queue is empty.
 * A photon enters on S1 (y = 0) along w_L, at the point its entry word gives in the tube
 * (ppb_mc_entry_x). Returns the restarted lanes' bits. */
PPB_MC_HOT uint ppb_mc_refill(const ppb_mc_params *p, ppb_mc_state *s, ppb_mc_queue *q, uint bits)
{
    vuint below = ((vuint)1 << PPB_MC_IOTA) - 1u;
    vulong m = (vulong)q->m + CONVERT_VULONG(popcount((vuint)bits & below)) * q->step;
    vint start = s->done & CONVERT_VINT(m < (vulong)q->n);
    vulong photon = (vulong)q->base + (vulong)q->stride * m;
    vuint c0 = CONVERT_VUINT(photon), c1 = CONVERT_VUINT(photon >> 32);
    vfloat x = p->med.tube ? ppb_mc_entry_x(p, q, bits) : (vfloat)0.0f;
    vfloat zero = (vfloat)0.0f;
    s->x = select(s->x, x, start), s->y = select(s->y, zero, start);
    s->wx = select(s->wx, (vfloat)p->light_x, start);
    s->wy = select(s->wy, (vfloat)p->light_y, start);
    s->wz = select(s->wz, zero, start);
    s->weight = select(s->weight, (vfloat)p->entry_weight, start);
    s->tau = select(s->tau, zero, start);
    s->capture = select(s->capture, zero, start);
    s->rgain = select(s->rgain, zero, start), s->rloss = select(s->rloss, zero, start);
    s->ctr0 = select(s->ctr0, c0, start), s->ctr1 = select(s->ctr1, c1, start);
    s->step = select(s->step, (vuint)0, start);
    s->nscat = select(s->nscat, (vint)0, start), s->capped = select(s->capped, (vint)0, start);
    s->need_tau |= start;
    s->active = select(s->active, start, s->done);
    s->done = s->left = s->side = (vint)0;
    q->m += (ulong)popcount(bits) * q->step;
    return ppb_mc_bits(start);
}

/* The cell (before the tally's offset) of one exit by the scalar double code: the exit's
 * surface (a side wall by wx, else S1/S2 by wy), its segment and its bin. */
inline size_t ppb_mc_exit_cell(const ppb_mc_params *p, const ppb_mc_edges *e, int side, float x,
                               float y, float wx, float wy, float wz)
{
    int surf = side ? (wx > 0.0f ? PPB_S4 : PPB_S3) : (wy > 0.0f ? PPB_S1 : PPB_S2);
    int seg = ppb_mc_segment(p, surf, x, y);
    int bin = ppb_mc_dir_bin(p, e, surf, (double)wx, (double)wy, (double)wz);
    return ppb_cell_index(p->offset[surf], seg, ppb_bin_count(p->ntheta, p->nphi), bin);
}

/* Cell (row and bin, before the tally's offset) of every lane's exit as it would be binned
 * now, in float vectors, and where float cannot decide (a value within its rounding of a segment,
 * theta or phi edge) a lane flag: that lane is binned by the scalar double code
 * (ppb_mc_segment, ppb_mc_dir_bin) instead, so every bin is the one that code gives (binning
 * exit by exit in scalar code was half of the kernel's time). The bounds: each float
 * quantity below is a few roundings (relative 2^-24 each) of values of magnitude <= 1 times
 * nseg or ntheta, so within 2e-7 nseg, 2e-7 ntheta and 3e-7 of the double one (itself within
 * 1e-15); the margins are ten times that and more, so outside them both sides of every edge
 * agree. The phi bin is the count of edges below phi (ppb_mc_phi_bin's c_k > 0, a prefix in
 * k), and a margin of 1e-5 on c_k also covers ppb_mc_phi_bin's own 1e-12 test. */
PPB_MC_HOT vint ppb_mc_vbins(const ppb_mc_params *p, const ppb_mc_edges *e, vint side, vfloat x,
                             vfloat y, vfloat wx, vfloat wy, vfloat wz, vint *exact)
{
    /* surface: S4/S3 on a side wall by wx, S1/S2 by wy (as the step put the photon there) */
    vint surf = select(select((vint)PPB_S2, (vint)PPB_S1, wy > 0.0f),
                       select((vint)PPB_S3, (vint)PPB_S4, wx > 0.0f), side);
    vfloat wn = select(wy, wx, side); /* +-mu: only its square is used */
    /* t = n x b (ppb_conventions.h): +x on S1, -x on S2, +y on S3, -y on S4 */
    vfloat wt = select(select(-wx, wx, surf == PPB_S1), select(-wy, wy, surf == PPB_S3), side);
    vfloat wb = fabs(wz);

    const float nt = (float)p->ntheta;
    vfloat vt = (1.0f - wn * wn) * nt;
    vint near = fabs(vt - rint(vt)) < 2e-6f * nt;
    vint kt = clamp(CONVERT_VINT(vt), 0, p->ntheta - 1);

    vint kp = (vint)0;
    for (int k = 1; k < p->nphi && k < PPB_MC_MAX_PHI; k++) {
        vfloat c = wb * e->cf[k] - wt * e->sf[k];
        kp -= c > 0.0f;
        near |= fabs(c) <= 1e-5f;
    }
    if (p->nphi > PPB_MC_MAX_PHI)
        near = (vint)-1;

    vint seg = (vint)0;
    if (p->med.tube) {
        const float w = (float)p->med.width, h = (float)p->med.height;
        vint top = ~side;
        vint nseg =
            select(select((vint)p->nseg[PPB_S2], (vint)p->nseg[PPB_S1], surf == PPB_S1),
                   select((vint)p->nseg[PPB_S3], (vint)p->nseg[PPB_S4], surf == PPB_S4), side);
        vfloat fseg = CONVERT_VFLOAT(nseg);
        vfloat vs = select(y + h, x + 0.5f * w, top) * select(fseg / h, fseg / w, top);
        near |= fabs(vs - rint(vs)) < 2e-6f * fseg;
        seg = clamp(CONVERT_VINT(vs), 0, nseg - 1);
    }
    vint off =
        select(select((vint)p->offset[PPB_S2], (vint)p->offset[PPB_S1], surf == PPB_S1),
               select((vint)p->offset[PPB_S3], (vint)p->offset[PPB_S4], surf == PPB_S4), side);
    *exact = near;
    int nbins = ppb_bin_count(p->ntheta, p->nphi);
    return (off + seg) * nbins + kt * p->nphi + kp; /* ppb_cell_index, ppb_bin_index per lane */
}

/* Tallies every finished lane (s->done), before ppb_mc_refill replaces it: the totals as lane
 * vectors, the cell additions of the scattered exits queued (ppb_mc_pending). */
PPB_MC_HOT void ppb_mc_tally(const ppb_mc_params *p, const ppb_mc_edges *e, const ppb_mc_state *s,
                             ppb_mc_pending *pend, ppb_mc_sums *sums, __global ulong *base,
                             __global ulong *spare)
{
    vint done = s->done, left = s->left & done, nscat = s->nscat;
    vulong zero = (vulong)0;
    vulong q = ppb_mc_vfixed(s->weight);
    vlong ldone = CONVERT_VLONG(done);
    sums->ballistic += select(zero, q, CONVERT_VLONG(left & (nscat == 0)));
    sums->capture += select(zero, ppb_mc_vfixed(s->capture), ldone);
    sums->rgain += select(zero, ppb_mc_vfixed(s->rgain), ldone);
    sums->rloss += select(zero, ppb_mc_vfixed(s->rloss), ldone);
    sums->events += select(zero, CONVERT_VULONG(nscat), ldone);
    sums->capped += select(zero, CONVERT_VULONG(s->capped), ldone);

    vint scat = left & (nscat != 0);
    uint sbits = ppb_mc_bits(scat);
    if (!sbits)
        return;
    vint exact;
    vint cellv = ppb_mc_vbins(p, e, s->side, s->x, s->y, s->wx, s->wy, s->wz, &exact);
    int cells[LANES], ns[LANES];
    ulong qs[LANES];
    VSTORE(cellv, 0, cells), VSTORE(nscat, 0, ns), VSTORE(q, 0, qs);
    uint xbits = ppb_mc_bits(exact & scat);
    size_t exact_cell[LANES];
    if (xbits) { /* rare: an exit within float's rounding of an edge */
        float x[LANES], y[LANES], wx[LANES], wy[LANES], wz[LANES];
        int side[LANES];
        VSTORE(s->x, 0, x), VSTORE(s->y, 0, y), VSTORE(s->wx, 0, wx), VSTORE(s->wy, 0, wy);
        VSTORE(s->wz, 0, wz), VSTORE(s->side, 0, side);
        for (uint b = xbits; b; b &= b - 1) {
            int l = ppb_mc_low_lane(b);
            exact_cell[l] = ppb_mc_exit_cell(p, e, side[l], x[l], y[l], wx[l], wy[l], wz[l]);
        }
    }
    for (uint b = sbits; b; b &= b - 1) {
        int l = ppb_mc_low_lane(b);
        size_t cell = (xbits >> l) & 1 ? exact_cell[l] : (size_t)(uint)cells[l];
        PPB_MC_PREFETCH(base + PPB_MC_TALLY_ALL * p->ncells + cell);
        pend->cell[pend->n] = PPB_MC_TALLY_ALL * p->ncells + cell, pend->q[pend->n++] = qs[l];
        if (ns[l] == 1)
            PPB_MC_PREFETCH(base + PPB_MC_TALLY_ONCE * p->ncells + cell);
        /* mc1's addition, kept only for a once-scattered photon (no branch to mispredict) */
        pend->cell[pend->n] = PPB_MC_TALLY_ONCE * p->ncells + cell, pend->q[pend->n] = qs[l];
        pend->n += ns[l] == 1;
        if (pend->n > PPB_MC_PEND - 2)
            ppb_mc_flush(pend, base, spare);
    }
}

/* ppb_refract_cos (ppb_fresnel.h) on every lane: the same double operations in the same order,
 * so each lane's value is the scalar one bit for bit (vector double arithmetic is IEEE, as
 * scalar; tests/kernels/mc_check.cl checks it for test_vector_fresnel_matches_scalar). */
PPB_MC_HOT vdouble ppb_mc_vrefract_cos(vdouble cos_i, double n_rel)
{
    vdouble sin2_t = (1.0 - cos_i * cos_i) / (n_rel * n_rel);
    return select(sqrt(1.0 - sin2_t), (vdouble)-1.0, sin2_t >= 1.0);
}

/* ppb_fresnel (ppb_fresnel.h) on every lane, given the lane's ppb_refract_cos (cos_t): the same
 * operations in the same order; 1 under total internal reflection (cos_t < 0). */
PPB_MC_HOT vdouble ppb_mc_vfresnel(vdouble cos_i, vdouble cos_t, double n_rel)
{
    vdouble rs = (cos_i - n_rel * cos_t) / (cos_i + n_rel * cos_t);
    vdouble rp = (n_rel * cos_i - cos_t) / (n_rel * cos_i + cos_t);
    return select(0.5 * (rs * rs + rp * rp), (vdouble)1.0, cos_t < 0.0);
}

/* n > 1: every lane whose photon has reached a wall (*left; side: a side wall), all lanes at
 * once. With probability F(cos theta_i) (r, the step's unused fourth word) it is reflected
 * specularly and flies on (its *left cleared); else it leaves along the refracted air-side
 * direction (tangential components times n, Snell), which ppb_mc_tally bins. Total internal
 * reflection has F = 1. In double, as ppb_fresnel.h (that scalar code lane by lane,
 * through memory, was a quarter of the kernel's time at n = 1.4). */
PPB_MC_HOT void ppb_mc_boundaries(const ppb_mc_params *p, ppb_mc_state *s, vint *left, vint side,
                                  vuint r)
{
    vlong side_l = CONVERT_VLONG(side);
    vdouble wx = CONVERT_VDOUBLE(s->wx), wy = CONVERT_VDOUBLE(s->wy);
    vdouble wn = select(wy, wx, side_l);
    vdouble cos_i = fabs(wn);
    double inv_n = 1.0 / p->med.n, n = p->med.n;
    vdouble cos_t = ppb_mc_vrefract_cos(cos_i, inv_n);
    vdouble f = ppb_mc_vfresnel(cos_i, cos_t, inv_n);
    vlong reflect = (cos_t < 0.0) | (CONVERT_VDOUBLE(ppb_mc_uniform(r)) < f);
    vint at = *left, bounce = at & CONVERT_VINT(reflect), leave = at & ~bounce;
    /* reflected: the normal component reversed */
    vfloat rx = select(s->wx, -s->wx, side), ry = select(-s->wy, s->wy, side);
    /* left: the air-side direction, the normal component the refracted cosine */
    vdouble out = copysign(cos_t, wn);
    vdouble ta = select(n * wx, out, side_l), tb = select(out, n * wy, side_l);
    vdouble tz = n * CONVERT_VDOUBLE(s->wz);
    s->wx = select(select(s->wx, rx, bounce), CONVERT_VFLOAT(ta), leave);
    s->wy = select(select(s->wy, ry, bounce), CONVERT_VFLOAT(tb), leave);
    s->wz = select(s->wz, CONVERT_VFLOAT(tz), leave);
    *left = leave;
}

/* One step of every flying lane: a flight leg to the next interaction, the step plane or a
 * wall, then (at an interaction) implicit capture, HG scattering and roulette. A leg that
 * reaches the step plane stops there with its remaining optical depth; a straight line crosses
 * the plane at most once, so a flight takes at most two legs. A lane that finishes (leaves or
 * dies) is marked done and keeps its state. */
PPB_MC_HOT void ppb_mc_step(const ppb_mc_params *p, ppb_mc_state *s, const float *medium)
{
    /* The float tube (mc_params.h): W, H and step_x rounded to float. */
    const float half_w = 0.5f * (float)p->med.width, sx = (float)p->med.step_x;
    const float h = (float)p->med.height;
    vint active = s->active;
    vfloat x = s->x, y = s->y;
    vfloat wx = s->wx, wy = s->wy, wz = s->wz;

    ppb_mc_vctr c = {s->ctr0, s->ctr1, s->step, (vuint)0};
    c = ppb_mc_philox(c, (uint)p->seed, (uint)(p->seed >> 32));
    s->step += 1u;
    vfloat tau = select(s->tau, -ppb_mc_log(ppb_mc_uniform(c.v0)), s->need_tau);

    /* Distances to the walls (tube sides only in tube mode) and to the step plane. Lanes
     * moving parallel to a wall divide by zero; select() discards those values. */
    vfloat inf = (vfloat)INFINITY;
    vfloat dx = inf;
    if (p->med.tube) /* the wall ahead's offset, then one division */
        dx = select(inf, select(-half_w - x, half_w - x, wx > 0.0f) / wx, wx != 0.0f);
    vfloat dy = select(inf, select(-h - y, -y, wy > 0.0f) / wy, wy != 0.0f);
    vfloat d_wall = fmin(dx, dy);
    /* medium: sigma_t left/right, 1/sigma_t left/right, alpha left/right (ppb_conventions.h) */
    vfloat sigma = (vfloat)medium[0], inv_sigma = (vfloat)medium[2], d_plane = inf;
    if (p->med.step == PPB_STEP_DENSITY) {
        /* A point on the plane belongs to the side it moves into (x >= step_x is right). */
        vint right = (x > sx) | ((x == sx) & (wx >= 0.0f));
        sigma = select(sigma, (vfloat)medium[1], right);
        inv_sigma = select(inv_sigma, (vfloat)medium[3], right);
        vint toward = (right & (wx < 0.0f)) | (~right & (wx > 0.0f));
        d_plane = select(inf, (sx - x) / wx, toward);
    }
    vfloat d_leg = fmin(d_wall, d_plane);
    vfloat dist = tau * inv_sigma;
    vint inter = (dist < d_leg) & active;
    vint cross = ~inter & (d_plane < d_wall) & active;
    vint left = ~inter & ~cross & active;
    vfloat go = select(d_leg, dist, inter);
    x += go * wx;
    y += go * wy;
    x = select(x, (vfloat)sx, cross); /* exactly on the plane: the side test sees the crossing */
    s->tau = select(tau, fmax(0.0f, tau - d_leg * sigma), cross);
    s->need_tau = ~cross;
    vint side = left & (dx <= dy);
    x = select(x, select((vfloat)-half_w, (vfloat)half_w, wx > 0.0f), side);
    y = select(y, select((vfloat)-h, (vfloat)0.0f, wy > 0.0f), left & ~side);

    /* Interaction: implicit capture with the albedo at the point, then scattering. */
    vfloat alpha = (vfloat)medium[4];
    if (p->med.step == PPB_STEP_ALBEDO)
        alpha = select(alpha, (vfloat)medium[5], x >= sx);
    vfloat weight = s->weight;
    s->capture = s->capture + select((vfloat)0.0f, weight * (1.0f - alpha), inter);
    weight = select(weight, weight * alpha, inter);
    vint nscat = s->nscat - inter;
    s->nscat = nscat;

    const float g = (float)p->med.g;
    vfloat ct = ppb_mc_hg_cos(g, 0.5f / g, ppb_mc_uniform(c.v1));
    vfloat cp, sp = ppb_mc_sincos2pi(ppb_mc_uniform(c.v2), &cp);
    /* New direction (MCML Eq. 3.30-3.31 with z as the reference axis; w.z = 0 at entry, so
     * the pole case is rare), then one Newton step for 1/|n| so round-off cannot build up. */
    vfloat st = sqrt(fmax(0.0f, 1.0f - ct * ct));
    vfloat r = sqrt(fmax(1e-12f, 1.0f - wz * wz)), st_r = st / r;
    vfloat nx = st_r * (wx * wz * cp - wy * sp) + wx * ct;
    vfloat ny = st_r * (wy * wz * cp + wx * sp) + wy * ct;
    vfloat nz = -st * cp * r + wz * ct;
    vint pole = fabs(wz) > 0.99999f;
    nx = select(nx, st * cp, pole);
    ny = select(ny, st * sp, pole);
    nz = select(nz, copysign(ct, wz), pole);
    vfloat renorm = 1.5f - 0.5f * (nx * nx + ny * ny + nz * nz);
    s->wx = select(wx, nx * renorm, inter);
    s->wy = select(wy, ny * renorm, inter);
    s->wz = select(wz, nz * renorm, inter);

    /* Russian roulette: survive with probability 1/M at M times the weight (M = 8, so the test
     * u < 1/M on the 2^-23 grid has probability exactly 1/M). alpha = 0 ends a photon too.
     * Past the event cap every interaction is a roulette (mc_params.h). */
    vint over_cap = inter & (nscat > PPB_MC_EVENT_CAP) & (weight < PPB_MC_CAP_WMAX);
    s->capped = s->capped - over_cap;
    vint roulette = inter & ((weight < PPB_MC_ROULETTE_W) | over_cap);
    vint survive = ppb_mc_uniform(c.v3) < 1.0f / PPB_MC_ROULETTE_M;
    s->rgain =
        s->rgain + select((vfloat)0.0f, weight * (PPB_MC_ROULETTE_M - 1.0f), roulette & survive);
    s->rloss = s->rloss + select((vfloat)0.0f, weight, roulette & ~survive);
    weight = select(weight, select((vfloat)0.0f, weight * PPB_MC_ROULETTE_M, survive), roulette);
    vint dead = inter & (weight <= 0.0f);

    /* A finished lane stays where it left (the step moved it by its wall distance). */
    s->x = select(s->x, x, active), s->y = select(s->y, y, active);
    s->weight = weight;
    if (p->med.n > 1.0 && ppb_mc_bits(left))
        ppb_mc_boundaries(p, s, &left, side, c.v3);
    vint finished = left | dead;
    s->done |= finished, s->left |= left, s->side |= side & left;
    s->active &= ~finished;
}

/* The global size is batches x P, P a multiple of the work-group size L (the host makes it
 * so). Work-group w traces the chunk's photons of batch b = w mod batches (i % batches == b),
 * its work-item j being the q-th of the batch, q = (w / batches) L + j, which takes the q-th,
 * (q + P)-th, ... of them. A work-group then stays inside one batch, so the cell tallies it
 * updates are one batch's slice, and consecutive work-groups, which a CPU runs at the same time
 * on its cores, update different slices (two cores adding into the same lines of one
 * slice pass them back and forth). A work-item's totals are summed privately with one atomic
 * per total at the end. Which work-item or lane traces a photon never changes the photon's
 * path, and integer sums do not depend on their order, so any global size, work-group size,
 * lane count or chunking gives the same tallies. */
__kernel void ppb_mc_trace_kernel(const ppb_mc_params p, __global ulong *cells,
                                  __global ulong *totals)
{
    const ulong batches = (ulong)p.batches;
    const ulong per_batch = get_global_size(0) / batches;
    const ulong group = get_group_id(0), wg_size = get_local_size(0);
    const int batch = (int)(group % batches);
    const ulong q0 = group / batches * wg_size + get_local_id(0);
    /* The chunk's photons of this batch: first + off + batches m, m = 0 .. n - 1. */
    const ulong off = ((ulong)batch + batches - p.first % batches) % batches;
    const ulong n = off < p.count ? (p.count - off - 1) / batches + 1 : 0;
    if (q0 >= n)
        return;
    __global ulong *base = cells + (size_t)batch * PPB_MC_NTALLY * p.ncells;

    /* The medium's two sides from the shared conventions (x < step_x left, x >= step_x right). */
    float medium[6];
    const ppb_medium *M = &p.med;
    medium[0] = (float)ppb_medium_sigma_t(M, M->step_x - 1.0);
    medium[1] = (float)ppb_medium_sigma_t(M, M->step_x);
    medium[2] = 1.0f / medium[0], medium[3] = 1.0f / medium[1];
    medium[4] = (float)ppb_medium_albedo(M, M->step_x - 1.0);
    medium[5] = (float)ppb_medium_albedo(M, M->step_x);

    ppb_mc_edges edges;
    ppb_mc_edges_init(&p, &edges);

    ppb_mc_sums sums;
    sums.ballistic = sums.capture = sums.rgain = sums.rloss = sums.events = sums.capped = (vulong)0;
    ppb_mc_pending pend;
    pend.n = 0;
    __global ulong *spare = totals + (size_t)batch * PPB_MC_NTOT + PPB_MC_NTOT - 1;
    ppb_mc_state s = {0};
    s.done = (vint)-1; /* every lane finished: the first refill fills them all */
    ppb_mc_queue queue = {q0, n, per_batch, p.first + off, batches};
    queue.used = 0;
    if (p.med.tube)
        ppb_mc_entry_words(&p, &queue, q0, queue.word);
    uint flying = ppb_mc_refill(&p, &s, &queue, (1u << LANES) - 1u);
    while (flying) {
        ppb_mc_step(&p, &s, medium);
        uint done = ppb_mc_bits(s.done);
        flying &= ~done;
        if (popcount(done) < PPB_MC_REFILL && flying)
            continue;
        ppb_mc_tally(&p, &edges, &s, &pend, &sums, base, spare);
        flying |= ppb_mc_refill(&p, &s, &queue, done);
    }

    ppb_mc_flush(&pend, base, spare);
    __global ulong *tot = totals + (size_t)batch * PPB_MC_NTOT;
    atom_add(tot + PPB_MC_T_BALLISTIC, ppb_mc_hsum(&sums.ballistic));
    atom_add(tot + PPB_MC_T_CAPTURE, ppb_mc_hsum(&sums.capture));
    atom_add(tot + PPB_MC_T_EVENTS, ppb_mc_hsum(&sums.events));
    atom_add(tot + PPB_MC_T_RGAIN, ppb_mc_hsum(&sums.rgain));
    atom_add(tot + PPB_MC_T_RLOSS, ppb_mc_hsum(&sums.rloss));
    atom_add(tot + PPB_MC_T_CAPPED, ppb_mc_hsum(&sums.capped));
}
