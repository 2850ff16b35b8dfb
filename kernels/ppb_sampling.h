/* ppb_sampling.h: the Monte Carlo kernel's random variates, shared by kernels/mc.cl and the
 * sampler checks of tests/test_mc.c (which compile them alone, so what they test is the code the
 * transport runs).
 *
 * Owns: a Philox output word to a uniform in (0, 1), the Henyey-Greenstein scattering cosine by
 * inversion, and the azimuth 2 pi u as its sine and cosine. OpenCL C only, on the lane vector
 * types of the including kernel: vfloat, vint and vuint of PPB_MC_LANES lanes and their
 * conversions CONVERT_VFLOAT and CONVERT_VINT (mc.cl defines them before including this). */
#ifndef PPB_SAMPLING_H
#define PPB_SAMPLING_H

/* Philox output word to a uniform in (0, 1): 23 bits plus half a step, exact in float, never 0
 * (log) nor 1. */
inline vfloat ppb_mc_uniform(vuint r)
{
    return (CONVERT_VFLOAT(r >> 9) + 0.5f) * 0x1p-23f;
}
inline float ppb_mc_uniform1(uint r)
{
    return ((float)(r >> 9) + 0.5f) * 0x1p-23f;
}

/* sin and cos of 2 pi u for u in (0, 1): reduction to the nearest quadrant (exact in float),
 * then Taylor polynomials on [-pi/4, pi/4] (truncation below 3e-8). */
inline vfloat ppb_mc_sincos2pi(vfloat u, vfloat *c)
{
    vfloat t = 4.0f * u;
    vfloat q = floor(t + 0.5f);
    vfloat r = (t - q) * 1.57079632679f;
    vfloat r2 = r * r;
    vfloat sr =
        r *
        (1.0f + r2 * (-1.0f / 6 + r2 * (1.0f / 120 + r2 * (-1.0f / 5040 + r2 * (1.0f / 362880)))));
    vfloat cr = 1.0f + r2 * (-0.5f + r2 * (1.0f / 24 + r2 * (-1.0f / 720 + r2 * (1.0f / 40320))));
    vint quadrant = CONVERT_VINT(q) & 3;
    vint q1 = quadrant == 1, q2 = quadrant == 2, q3 = quadrant == 3;
    vfloat s = select(select(select(sr, cr, q1), -sr, q2), -cr, q3);
    *c = select(select(select(cr, -sr, q1), -cr, q2), sr, q3);
    return s;
}

/* Henyey-Greenstein cosine by inversion (e.g. Wang, Jacques & Zheng 1995, MCML Eq. 3.28). */
inline vfloat ppb_mc_hg_cos(float g, float inv_2g, vfloat u)
{
    if (fabs(g) < 1e-4f)
        return 2.0f * u - 1.0f;
    vfloat s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
    return clamp((1.0f + g * g - s * s) * inv_2g, -1.0f, 1.0f);
}

#endif
