/* mc_rgb.cl: the multi-channel photon Monte Carlo (docs/methods.md, Monte Carlo: several
 * channels in one run): one path per photon carries a weight per colour channel, the channels'
 * media differing in sigma_t, albedo and g (n is shared), by hero-channel sampling with the
 * balance heuristic over channels (Wilkie et al. 2014, "Hero Wavelength Spectral Sampling"; Veach
 * 1997, Sec. 9.2).
 *
 * Each photon draws its hero channel h uniformly (Philox counter (i mod 2^32, i / 2^32, 0, 2),
 * word 0: h = floor(nch u32 / 2^32), uniform within 2^-32, far below the float rounding of any
 * weight) and flies, scatters and rolls its roulette exactly as mc.cl's photon i would in the
 * hero's medium, with the same random numbers (the step counters (i mod 2^32, i / 2^32, k, 0)).
 * The path's density under channel k's sampling is p_k = prod over legs exp(-sigma_k d) times
 * sigma_k at each interaction times HG(cos; g_k) at each scattering (Fresnel choices and the
 * entry are the same for every channel, n being shared). Since the hero is drawn uniformly, the
 * path's density is the mixture (1/nch) sum_k p_k, and channel c's estimator is
 *     W_c = a_c p_c / ((1/nch) sum_k p_k) = a_c nch e_c / sum_k e_k,  e_k = exp(l_k - max l),
 * with l_k = log(p_k / p_h), built leg by leg (-(sigma_k - sigma_h) d on each leg within one side
 * of the density step, log(sigma_k / sigma_h) at an interaction, the HG log ratio at a scattering
 * when g differs), and a_c the entry weight times channel c's albedos (implicit capture) and the
 * roulette factors. W_c is unbiased for channel c (the mixture's density is positive wherever
 * p_c is) and at most nch a_c (balance heuristic). Implicit capture tallies W_c (1 - alpha_c) at
 * each interaction with the path up to it: a prefix's density under the mixture is the mixture of
 * its densities, so that too is unbiased for channel c's absorption.
 *
 * Roulette (mc_params.h's rule) tests the largest a_c, so W_c <= nch 8 PPB_MC_CAP_WMAX keeps the
 * fixed-point tallies in range; it is applied to every channel at once (same survival, same
 * factor), unbiased for each.
 *
 * With nch equal channels every l_k is 0, e_k = 1 and W_c = a_c = mc.cl's weight exactly, so the
 * tallies of each channel are mc.cl's bytes for the same seed (tests/test_mc_rgb.c checks it).
 *
 * Layout, chunking and reproducibility are mc.cl's (included below, whose functions this file
 * uses unchanged): a photon's path depends only on the seed and its index. ppb_rgb_step is
 * ppb_mc_step with the channels added, not a call of it: mc.cl's text (with its headers) is in
 * the key of every cached and shipped reference (mc_cache.h), so splitting its step into parts
 * both kernels share would re-key references/; that belongs with their next regeneration. */
#include "mc.cl"
#include "mc_rgb_params.h"

#ifndef PPB_MC_NCH
#define PPB_MC_NCH 3
#endif

/* exp(x) for x <= 0 in plain arithmetic (as mc.cl's log: no library variant per vector width):
 * x = k ln 2 + r, |r| <= ln 2 / 2, Cephes expf's polynomial for exp(r) (relative error below
 * 2e-7), times 2^k by the exponent bits. Below -87 (2^-126) it is 0; exp(0) is 1 exactly. */
PPB_MC_HOT vfloat ppb_rgb_exp(vfloat x)
{
    vint tiny = x < -87.0f;
    x = fmax(x, -87.0f);
    vfloat k = floor(x * 1.44269504089f + 0.5f);
    vfloat r = x - k * 0.693359375f + k * 2.12194440e-4f;
    vfloat p = 1.9875691500e-4f;
    p = p * r + 1.3981999507e-3f;
    p = p * r + 8.3334519073e-3f;
    p = p * r + 4.1665795894e-2f;
    p = p * r + 1.6666665459e-1f;
    p = p * r + 5.0000001201e-1f;
    vfloat e = p * r * r + r + 1.0f;
    vfloat two_k = AS_VFLOAT((CONVERT_VINT(k) + 127) << 23);
    return select(e * two_k, (vfloat)0.0f, tiny);
}

/* v[hero] on every lane. */
PPB_MC_HOT vfloat ppb_rgb_pick(const vfloat *v, vint hero)
{
    vfloat out = v[0];
#pragma unroll
    for (int k = 1; k < PPB_MC_NCH; k++)
        out = select(out, v[k], hero == k);
    return out;
}

/* The lanes' state: mc.cl's (the hero's path; its weight is unused) and per channel the log
 * density ratio, the weight before the balance heuristic and what its tallies need. */
typedef struct ppb_rgb_state {
    ppb_mc_state s;
    vfloat l[PPB_MC_NCH];       /* log p_k(path) / p_hero(path) */
    vfloat a[PPB_MC_NCH];       /* entry weight x albedos x roulette factors */
    vfloat capture[PPB_MC_NCH]; /* W_k (1 - alpha_k) summed over interactions */
    vfloat rgain[PPB_MC_NCH], rloss[PPB_MC_NCH];
    vint hero;
} ppb_rgb_state;

/* W_k = a_k nch e_k / sum e_j (the balance heuristic over channels), every lane. */
PPB_MC_HOT void ppb_rgb_weights(const ppb_rgb_state *r, vfloat *w)
{
    vfloat m = r->l[0];
#pragma unroll
    for (int k = 1; k < PPB_MC_NCH; k++)
        m = fmax(m, r->l[k]);
    vfloat e[PPB_MC_NCH], sum = (vfloat)0.0f;
#pragma unroll
    for (int k = 0; k < PPB_MC_NCH; k++)
        e[k] = ppb_rgb_exp(r->l[k] - m), sum += e[k];
    vfloat scale = (float)PPB_MC_NCH / sum;
#pragma unroll
    for (int k = 0; k < PPB_MC_NCH; k++)
        w[k] = r->a[k] * (e[k] * scale);
}

/* HG cosine with a g per lane: ppb_sampling.h's inversion, isotropic where |g| < 1e-4. */
PPB_MC_HOT vfloat ppb_rgb_hg_cos(vfloat g, vfloat u)
{
    vfloat s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
    vfloat ct = clamp((1.0f + g * g - s * s) / (2.0f * g), -1.0f, 1.0f);
    return select(ct, 2.0f * u - 1.0f, fabs(g) < 1e-4f);
}

/* One step of every flying lane: mc.cl's ppb_mc_step in the hero's medium (the same operations
 * in the same order on the hero's path, so equal channels give its bytes), with each channel's
 * density ratio and weight carried along. med[k * 6 + j]: channel k's sigma_t left/right,
 * 1/sigma_t left/right, alpha left/right, as mc.cl's medium[]. */
PPB_MC_HOT void ppb_rgb_step(const ppb_mc_params *p, const ppb_mc_rgb_params *q, ppb_rgb_state *r,
                             const float *med)
{
    ppb_mc_state *s = &r->s;
    const float half_w = 0.5f * (float)p->med.width, sx = (float)p->med.step_x;
    const float h = (float)p->med.height;
    vint active = s->active;
    vfloat x = s->x, y = s->y;
    vfloat wx = s->wx, wy = s->wy, wz = s->wz;

    ppb_mc_vctr c = {s->ctr0, s->ctr1, s->step, (vuint)0};
    c = ppb_mc_philox(c, (uint)p->seed, (uint)(p->seed >> 32));
    s->step += 1u;
    vfloat tau = select(s->tau, -ppb_mc_log(ppb_mc_uniform(c.v0)), s->need_tau);

    vfloat inf = (vfloat)INFINITY;
    vfloat dx = inf;
    if (p->med.tube)
        dx = select(inf, select(-half_w - x, half_w - x, wx > 0.0f) / wx, wx != 0.0f);
    vfloat dy = select(inf, select(-h - y, -y, wy > 0.0f) / wy, wy != 0.0f);
    vfloat d_wall = fmin(dx, dy);
    /* Every channel's sigma_t (and its log) on the lane's side of the step, the hero's picked. */
    vfloat sig[PPB_MC_NCH], inv[PPB_MC_NCH], lsig[PPB_MC_NCH], d_plane = inf;
    vint right = (vint)0;
    if (p->med.step == PPB_STEP_DENSITY) {
        right = (x > sx) | ((x == sx) & (wx >= 0.0f));
        vint toward = (right & (wx < 0.0f)) | (~right & (wx > 0.0f));
        d_plane = select(inf, (sx - x) / wx, toward);
    }
#pragma unroll
    for (int k = 0; k < PPB_MC_NCH; k++) {
        sig[k] = select((vfloat)med[k * 6 + 0], (vfloat)med[k * 6 + 1], right);
        inv[k] = select((vfloat)med[k * 6 + 2], (vfloat)med[k * 6 + 3], right);
        lsig[k] = select((vfloat)q->log_sigma_t[k][0], (vfloat)q->log_sigma_t[k][1], right);
    }
    vfloat sigma = ppb_rgb_pick(sig, r->hero), inv_sigma = ppb_rgb_pick(inv, r->hero);
    vfloat lsig_h = ppb_rgb_pick(lsig, r->hero);
    vfloat d_leg = fmin(d_wall, d_plane);
    vfloat dist = tau * inv_sigma;
    vint inter = (dist < d_leg) & active;
    vint cross = ~inter & (d_plane < d_wall) & active;
    vint left = ~inter & ~cross & active;
    vfloat go = select(d_leg, dist, inter);
    /* The leg's density ratios: exp(-(sigma_k - sigma_h) go), times sigma_k / sigma_h when it
     * ends in an interaction (a leg lies on one side of the step). */
#pragma unroll
    for (int k = 0; k < PPB_MC_NCH; k++) {
        vfloat dl = -(sig[k] - sigma) * go + select((vfloat)0.0f, lsig[k] - lsig_h, inter);
        r->l[k] = select(r->l[k], r->l[k] + dl, active);
    }
    x += go * wx;
    y += go * wy;
    x = select(x, (vfloat)sx, cross);
    s->tau = select(tau, fmax(0.0f, tau - d_leg * sigma), cross);
    s->need_tau = ~cross;
    vint side = left & (dx <= dy);
    x = select(x, select((vfloat)-half_w, (vfloat)half_w, wx > 0.0f), side);
    y = select(y, select((vfloat)-h, (vfloat)0.0f, wy > 0.0f), left & ~side);

    /* Interaction: each channel's implicit capture with its albedo at the point, weighted by
     * the balance heuristic of the path up to here; then the weights after capture. */
    vfloat w[PPB_MC_NCH], amax = (vfloat)0.0f;
    ppb_rgb_weights(r, w);
#pragma unroll
    for (int k = 0; k < PPB_MC_NCH; k++) {
        vfloat alpha = (vfloat)med[k * 6 + 4];
        if (p->med.step == PPB_STEP_ALBEDO)
            alpha = select(alpha, (vfloat)med[k * 6 + 5], x >= sx);
        r->capture[k] = r->capture[k] + select((vfloat)0.0f, w[k] * (1.0f - alpha), inter);
        r->a[k] = select(r->a[k], r->a[k] * alpha, inter);
        w[k] = select(w[k], w[k] * alpha, inter);
        amax = fmax(amax, r->a[k]);
    }
    vint nscat = s->nscat - inter;
    s->nscat = nscat;

    /* Scattering by the hero's g; with g differing, each channel's HG density ratio. */
    vfloat ct;
    if (q->same_g) {
        const float g = q->g[0];
        ct = ppb_mc_hg_cos(g, 0.5f / g, ppb_mc_uniform(c.v1));
    } else {
        vfloat gk[PPB_MC_NCH], lk[PPB_MC_NCH];
#pragma unroll
        for (int k = 0; k < PPB_MC_NCH; k++)
            gk[k] = (vfloat)(fabs(q->g[k]) < 1e-4f ? 0.0f : q->g[k]); /* as the sampler draws */
        vfloat gh = ppb_rgb_pick(gk, r->hero);
        ct = ppb_rgb_hg_cos(gh, ppb_mc_uniform(c.v1));
        /* log HG(ct; g) = log(1 - g^2) - 1.5 log(1 + g^2 - 2 g ct) + const */
#pragma unroll
        for (int k = 0; k < PPB_MC_NCH; k++)
            lk[k] = q->log_1mg2[k] - 1.5f * ppb_mc_log(1.0f + gk[k] * gk[k] - 2.0f * gk[k] * ct);
        vfloat lh = ppb_rgb_pick(lk, r->hero);
#pragma unroll
        for (int k = 0; k < PPB_MC_NCH; k++)
            r->l[k] = select(r->l[k], r->l[k] + (lk[k] - lh), inter);
    }
    vfloat cp, sp = ppb_mc_sincos2pi(ppb_mc_uniform(c.v2), &cp);
    vfloat st = sqrt(fmax(0.0f, 1.0f - ct * ct));
    vfloat rr = sqrt(fmax(1e-12f, 1.0f - wz * wz)), st_r = st / rr;
    vfloat nx = st_r * (wx * wz * cp - wy * sp) + wx * ct;
    vfloat ny = st_r * (wy * wz * cp + wx * sp) + wy * ct;
    vfloat nz = -st * cp * rr + wz * ct;
    vint pole = fabs(wz) > 0.99999f;
    nx = select(nx, st * cp, pole);
    ny = select(ny, st * sp, pole);
    nz = select(nz, copysign(ct, wz), pole);
    vfloat renorm = 1.5f - 0.5f * (nx * nx + ny * ny + nz * nz);
    s->wx = select(wx, nx * renorm, inter);
    s->wy = select(wy, ny * renorm, inter);
    s->wz = select(wz, nz * renorm, inter);

    /* Roulette (mc.cl's rule) on the largest a_k, every channel together. */
    vint over_cap = inter & (nscat > PPB_MC_EVENT_CAP) & (amax < PPB_MC_CAP_WMAX);
    s->capped = s->capped - over_cap;
    vint roulette = inter & ((amax < PPB_MC_ROULETTE_W) | over_cap);
    vint survive = ppb_mc_uniform(c.v3) < 1.0f / PPB_MC_ROULETTE_M;
#pragma unroll
    for (int k = 0; k < PPB_MC_NCH; k++) {
        r->rgain[k] = r->rgain[k] +
                      select((vfloat)0.0f, w[k] * (PPB_MC_ROULETTE_M - 1.0f), roulette & survive);
        r->rloss[k] = r->rloss[k] + select((vfloat)0.0f, w[k], roulette & ~survive);
        r->a[k] =
            select(r->a[k], select((vfloat)0.0f, r->a[k] * PPB_MC_ROULETTE_M, survive), roulette);
    }
    amax = select(amax, select((vfloat)0.0f, amax * PPB_MC_ROULETTE_M, survive), roulette);
    vint dead = inter & (amax <= 0.0f);

    s->x = select(s->x, x, active), s->y = select(s->y, y, active);
    if (p->med.n > 1.0 && ppb_mc_bits(left))
        ppb_mc_boundaries(p, s, &left, side, c.v3);
    vint finished = left | dead;
    s->done |= finished, s->left |= left, s->side |= side & left;
    s->active &= ~finished;
}

/* mc.cl's refill, then each restarted lane's channels reset and its hero drawn. */
PPB_MC_HOT uint ppb_rgb_refill(const ppb_mc_params *p, ppb_rgb_state *r, ppb_mc_queue *queue,
                               uint bits)
{
    uint started = ppb_mc_refill(p, &r->s, queue, bits);
    vint start = ((((vuint)started) >> PPB_MC_IOTA) & 1u) != (vuint)0;
    ppb_mc_vctr c = {r->s.ctr0, r->s.ctr1, (vuint)0, (vuint)2};
    c = ppb_mc_philox(c, (uint)p->seed, (uint)(p->seed >> 32));
    vint hero = CONVERT_VINT((CONVERT_VULONG(c.v0) * (ulong)PPB_MC_NCH) >> 32);
    r->hero = select(r->hero, hero, start);
    vfloat zero = (vfloat)0.0f;
#pragma unroll
    for (int k = 0; k < PPB_MC_NCH; k++) {
        r->l[k] = select(r->l[k], zero, start);
        r->a[k] = select(r->a[k], (vfloat)p->entry_weight, start);
        r->capture[k] = select(r->capture[k], zero, start);
        r->rgain[k] = select(r->rgain[k], zero, start);
        r->rloss[k] = select(r->rloss[k], zero, start);
    }
    return started;
}

/* Tallies every finished lane once per channel through mc.cl's ppb_mc_tally, with the channel's
 * weight W_k and its capture and roulette sums in place of the state's. */
PPB_MC_HOT void ppb_rgb_tally(const ppb_mc_params *p, const ppb_mc_edges *e, const ppb_rgb_state *r,
                              ppb_mc_pending *pend, ppb_mc_sums *sums, __global ulong *const *base,
                              __global ulong *spare)
{
    vfloat w[PPB_MC_NCH];
    ppb_rgb_weights(r, w);
    for (int k = 0; k < PPB_MC_NCH; k++) {
        ppb_mc_state sk = r->s;
        sk.weight = w[k];
        sk.capture = r->capture[k], sk.rgain = r->rgain[k], sk.rloss = r->rloss[k];
        ppb_mc_tally(p, e, &sk, &pend[k], &sums[k], base[k], spare);
    }
}

/* mc.cl's ppb_mc_trace_kernel for PPB_MC_NCH channels: the same batches, work-groups and
 * photon order; channel k's tallies at cells and totals offset by k batches (mc_rgb_params.h). */
__kernel void ppb_mc_rgb_kernel(const ppb_mc_params p, __global ulong *cells,
                                __global ulong *totals, const ppb_mc_rgb_params q)
{
    const ulong batches = (ulong)p.batches;
    const ulong per_batch = get_global_size(0) / batches;
    const ulong group = get_group_id(0), wg_size = get_local_size(0);
    const int batch = (int)(group % batches);
    const ulong q0 = group / batches * wg_size + get_local_id(0);
    const ulong off = ((ulong)batch + batches - p.first % batches) % batches;
    const ulong n = off < p.count ? (p.count - off - 1) / batches + 1 : 0;
    if (q0 >= n)
        return;
    __global ulong *base[PPB_MC_NCH];
    for (int k = 0; k < PPB_MC_NCH; k++)
        base[k] = cells + ((size_t)k * p.batches + (size_t)batch) * PPB_MC_NTALLY * p.ncells;

    /* Each channel's medium as mc.cl's medium[], from the same float values. */
    float med[PPB_MC_NCH * 6];
    for (int k = 0; k < PPB_MC_NCH; k++) {
        med[k * 6 + 0] = q.sigma_t[k][0], med[k * 6 + 1] = q.sigma_t[k][1];
        med[k * 6 + 2] = 1.0f / med[k * 6 + 0], med[k * 6 + 3] = 1.0f / med[k * 6 + 1];
        med[k * 6 + 4] = q.albedo[k][0], med[k * 6 + 5] = q.albedo[k][1];
    }

    ppb_mc_edges edges;
    ppb_mc_edges_init(&p, &edges);

    ppb_mc_sums sums[PPB_MC_NCH];
    ppb_mc_pending pend[PPB_MC_NCH];
    for (int k = 0; k < PPB_MC_NCH; k++) {
        sums[k].ballistic = sums[k].capture = sums[k].rgain = (vulong)0;
        sums[k].rloss = sums[k].events = sums[k].capped = (vulong)0;
        pend[k].n = 0;
    }
    __global ulong *spare = totals + (size_t)batch * PPB_MC_NTOT + PPB_MC_NTOT - 1;
    ppb_rgb_state r = {0};
    r.s.done = (vint)-1;
    ppb_mc_queue queue = {q0, n, per_batch, p.first + off, batches};
    queue.used = 0;
    if (p.med.tube)
        ppb_mc_entry_words(&p, &queue, q0, queue.word);
    uint flying = ppb_rgb_refill(&p, &r, &queue, (1u << LANES) - 1u);
    while (flying) {
        ppb_rgb_step(&p, &q, &r, med);
        uint done = ppb_mc_bits(r.s.done);
        flying &= ~done;
        if (popcount(done) < PPB_MC_REFILL && flying)
            continue;
        ppb_rgb_tally(&p, &edges, &r, pend, sums, base, spare);
        flying |= ppb_rgb_refill(&p, &r, &queue, done);
    }

    for (int k = 0; k < PPB_MC_NCH; k++) {
        ppb_mc_flush(&pend[k], base[k], spare);
        __global ulong *tot = totals + ((size_t)k * p.batches + (size_t)batch) * PPB_MC_NTOT;
        atom_add(tot + PPB_MC_T_BALLISTIC, ppb_mc_hsum(&sums[k].ballistic));
        atom_add(tot + PPB_MC_T_CAPTURE, ppb_mc_hsum(&sums[k].capture));
        atom_add(tot + PPB_MC_T_EVENTS, ppb_mc_hsum(&sums[k].events));
        atom_add(tot + PPB_MC_T_RGAIN, ppb_mc_hsum(&sums[k].rgain));
        atom_add(tot + PPB_MC_T_RLOSS, ppb_mc_hsum(&sums[k].rloss));
        atom_add(tot + PPB_MC_T_CAPPED, ppb_mc_hsum(&sums[k].capped));
    }
}
