/* mc_check.cl: self-checks of the Monte Carlo kernel's vector code, run by tests/test_mc.c.
 * They compile the kernel's own text: mc.cl is included whole (built with -I
 * <root>/src/methods/mc and the trace's -D PPB_MC_LANES), so each check calls the very
 * functions the trace runs, and the trace's source (whose text the reference cache's key
 * hashes) holds no test code. */
#include "mc.cl"

/* The vector Philox (ppb_mc_philox) against Random123's philox4x32 on
 * varied counters and keys; counts mismatching words into *mismatches. */
__kernel void ppb_mc_philox_check(ulong seed, __global uint *mismatches)
{
    uint g = (uint)get_global_id(0);
    uint c0[LANES], c1[LANES], c2[LANES], c3[LANES];
    for (int l = 0; l < LANES; l++) {
        c0[l] = g * LANES + (uint)l, c1[l] = g ^ 0x9e3779b9u, c2[l] = (uint)l * 977u + g;
        c3[l] = g & 1;
    }
    ppb_mc_vctr c = {VLOAD(0, c0), VLOAD(0, c1), VLOAD(0, c2), VLOAD(0, c3)};
    c = ppb_mc_philox(c, (uint)seed, (uint)(seed >> 32));
    uint out[4][LANES];
    VSTORE(c.v0, 0, out[0]), VSTORE(c.v1, 0, out[1]), VSTORE(c.v2, 0, out[2]);
    VSTORE(c.v3, 0, out[3]);
    philox4x32_key_t k = {{(uint)seed, (uint)(seed >> 32)}};
    for (int l = 0; l < LANES; l++) {
        philox4x32_ctr_t s = {{c0[l], c1[l], c2[l], c3[l]}};
        philox4x32_ctr_t r = philox4x32(s, k);
        for (int w = 0; w < 4; w++)
            if (r.v[w] != out[w][l])
                atomic_inc(mismatches);
    }
}

/* ppb_mc_vrefract_cos and ppb_mc_vfresnel against the scalar
 * ppb_refract_cos and ppb_fresnel (ppb_fresnel.h) bit for bit, at relative index n_rel, on the
 * incidence cosines (g LANES + l + 0.5) / (global LANES) plus 0, 1 and the critical cosine
 * sqrt(1 - n_rel^2) and its neighbours (work-item 0; at 2 lanes only 0 and the critical one);
 * counts mismatching values into *mismatches. */
__kernel void ppb_mc_fresnel_check(double n_rel, __global uint *mismatches)
{
    uint g = (uint)get_global_id(0), total = (uint)get_global_size(0) * LANES;
    double c[LANES];
    for (int l = 0; l < LANES; l++)
        c[l] = ((double)(g * LANES + (uint)l) + 0.5) / (double)total;
    if (g == 0) {
        double crit = n_rel < 1.0 ? sqrt(1.0 - n_rel * n_rel) : 0.0;
        c[0] = 0.0, c[1] = 1.0;
        c[LANES - 1] = crit;
#if LANES >= 4
        c[2] = nextafter(crit, 0.0), c[3] = nextafter(crit, 1.0);
#endif
    }
    vdouble cos_i = VLOAD(0, c);
    vdouble cos_t = ppb_mc_vrefract_cos(cos_i, n_rel);
    vdouble f = ppb_mc_vfresnel(cos_i, cos_t, n_rel);
    double t[LANES], fl[LANES];
    VSTORE(cos_t, 0, t), VSTORE(f, 0, fl);
    for (int l = 0; l < LANES; l++) {
        if (as_ulong(t[l]) != as_ulong(ppb_refract_cos(c[l], n_rel)))
            atomic_inc(mismatches);
        if (as_ulong(fl[l]) != as_ulong(ppb_fresnel(c[l], n_rel)))
            atomic_inc(mismatches);
    }
}

/* ppb_mc_vbins, with the scalar fallback ppb_mc_finish takes on
 * the lanes it flags, against the conventions' own binning (ppb_segment_of, ppb_dir_bin with
 * atan2) on exits of every surface the params have: a quarter at random, a quarter with mu on
 * a theta edge (sin^2 theta = k / ntheta), a quarter with phi on a phi edge (k pi / nphi) and a
 * quarter at a segment edge, each rounded to float as a photon's state is. Counts into out[0]
 * the cells that differ, out[1] the lanes flagged for the fallback, out[2] the lanes checked. */
__kernel void ppb_mc_bins_check(const ppb_mc_params p, __global uint *out)
{
    uint g = (uint)get_global_id(0);
    ppb_mc_edges edges;
    ppb_mc_edges_init(&p, &edges);
    uint c0[LANES];
    for (int l = 0; l < LANES; l++)
        c0[l] = g * LANES + (uint)l;
    ppb_mc_vctr c = {VLOAD(0, c0), (vuint)0x5eed, (vuint)7, (vuint)3};
    c = ppb_mc_philox(c, (uint)p.seed, (uint)(p.seed >> 32));
    uint r[4][LANES];
    VSTORE(c.v0, 0, r[0]), VSTORE(c.v1, 0, r[1]), VSTORE(c.v2, 0, r[2]), VSTORE(c.v3, 0, r[3]);
    float fx[LANES], fy[LANES], fwx[LANES], fwy[LANES], fwz[LANES];
    int fside[LANES], fsurf[LANES];
    const int nsurf = p.med.tube ? 4 : 2;
    for (int l = 0; l < LANES; l++) {
        int kind = (int)(c0[l] % 4u), surf = (int)(r[0][l] % (uint)nsurf);
        double u1 = ((double)r[1][l] + 0.5) / 4294967296.0;
        double u2 = ((double)r[2][l] + 0.5) / 4294967296.0;
        double u3 = ((double)r[3][l] + 0.5) / 4294967296.0;
        double s2 = u1, phi = PPB_PI * u2, along = u3; /* sin^2 theta, phi, position in [0, 1) */
        if (kind == 1)
            s2 = (double)(r[1][l] % (uint)(p.ntheta + 1)) / p.ntheta;
        if (kind == 2)
            phi = (double)(r[2][l] % (uint)(p.nphi + 1)) * PPB_PI / p.nphi;
        int nseg = p.med.tube ? p.nseg[surf] : 1;
        if (kind == 3)
            along = (double)(r[3][l] % (uint)(nseg + 1)) / nseg;
        double mu = sqrt(1.0 - s2), st = sqrt(s2);
        double wt = st * cos(phi), wb = st * sin(phi) * ((r[0][l] >> 16) & 1 ? -1.0 : 1.0);
        double wx = mu * ppb_normal_x(surf) + wt * ppb_tangent_x(surf);
        double wy = mu * ppb_normal_y(surf) + wt * ppb_tangent_y(surf);
        double w = (double)(float)p.med.width, h = (double)(float)p.med.height, x, y;
        if (surf == PPB_S1 || surf == PPB_S2)
            x = -0.5 * w + along * w, y = surf == PPB_S1 ? 0.0 : -h;
        else
            x = surf == PPB_S3 ? -0.5 * w : 0.5 * w, y = -h + along * h;
        /* the state as floats; a float mu of 0 would leave the surface undecided, so it keeps
         * its outward sign */
        fwx[l] = (float)wx, fwy[l] = (float)wy, fwz[l] = (float)wb;
        if (surf == PPB_S1 && !(fwy[l] > 0.0f))
            fwy[l] = 1e-30f;
        if (surf == PPB_S4 && !(fwx[l] > 0.0f))
            fwx[l] = 1e-30f;
        fx[l] = (float)x, fy[l] = (float)y;
        fside[l] = -(surf == PPB_S3 || surf == PPB_S4), fsurf[l] = surf;
    }
    vint exact;
    vint cellv = ppb_mc_vbins(&p, &edges, VLOAD(0, fside), VLOAD(0, fx), VLOAD(0, fy),
                              VLOAD(0, fwx), VLOAD(0, fwy), VLOAD(0, fwz), &exact);
    int cells[LANES], ex[LANES];
    VSTORE(cellv, 0, cells), VSTORE(exact, 0, ex);
    for (int l = 0; l < LANES; l++) {
        size_t cell = (size_t)(uint)cells[l];
        if (ex[l]) {
            cell = ppb_mc_exit_cell(&p, &edges, fside[l], fx[l], fy[l], fwx[l], fwy[l], fwz[l]);
            atomic_inc(out + 1);
        }
        int surf = fsurf[l];
        double sv = (surf == PPB_S1 || surf == PPB_S2) ? (double)fx[l] : (double)fy[l];
        double w = (double)(float)p.med.width, h = (double)(float)p.med.height;
        int seg = p.med.tube ? ppb_segment_at(surf, sv, p.nseg[surf], w, h) : 0;
        int bin =
            ppb_dir_bin(surf, (double)fwx[l], (double)fwy[l], (double)fwz[l], p.ntheta, p.nphi);
        size_t ref = ppb_cell_index(p.offset[surf], seg, ppb_bin_count(p.ntheta, p.nphi), bin);
        if (cell != ref)
            atomic_inc(out);
        atomic_inc(out + 2);
    }
}
