#!/usr/bin/awk -f
# chi2_radiance.awk: a method's bins against the Monte Carlo's, or against another run's, read
# from radiance.csv (docs/reference.md, Outputs: method,surface,segment,s,theta_bin,phi_bin,
# radiance,stderr).
#
# One file:  awk -v m=rte2d -v ref=mc -f scripts/chi2_radiance.awk DIR/radiance.csv
#   per surface and over all: chi2 = sum over the bins (m - ref)^2 / (se_m^2 + se_ref^2), the
#   bins where either has no signal or both have se 0 left out; dof = the bins counted; z =
#   (chi2 - dof) / sqrt(2 dof), the normal deviate of a chi-square with dof degrees of freedom
#   (|z| > 3: the difference is beyond the noise); rel = the power-weighted relative RMS
#   sqrt(sum (m - ref)^2 / sum ref^2).
# Two files: awk -v m=rte2d -v ref=rte2d -f scripts/chi2_radiance.awk A/radiance.csv B/radiance.csv
#   m's bins of the first file against ref's of the second (a deterministic method against a
#   refined run of itself): rel per surface and the largest bin's relative difference (bins
#   above 1e-3 of the surface's largest), no chi2 (se 0).
BEGIN {
    FS = ",";
    if (m == "" || ref == "") {
        print "chi2_radiance: give the method and the reference: -v m=ID -v ref=ID" > "/dev/stderr";
        exit 2;
    }
}
FNR == 1 { nfile++; next }
{
    key = $2 "," $3 "," $5 "," $6;
    if (nfile == 1 && $1 == m) { vm[key] = $7; sm[key] = $8; surf[key] = $2; order[++n] = key }
    isref = (ARGC == 2 || nfile == 2) && $1 == ref;
    if (isref) {
        vr[key] = $7; sr[key] = $8;
        if (!($2 in peak) || $7 > peak[$2]) peak[$2] = $7;
    }
}
END {
    if (n == 0) { print "chi2_radiance: no rows of method " m > "/dev/stderr"; exit 2 }
    for (i = 1; i <= n; i++) {
        k = order[i];
        if (!(k in vr)) continue;
        s = surf[k];
        d = vm[k] - vr[k];
        dd[s] += d * d; rr[s] += vr[k] * vr[k];
        dd["all"] += d * d; rr["all"] += vr[k] * vr[k];
        if (vr[k] > 1e-3 * peak[s] && vr[k] > 0) {
            e = d / vr[k]; e = e < 0 ? -e : e;
            if (e > mx[s]) mx[s] = e;
            if (e > mx["all"]) mx["all"] = e;
        }
        v = sm[k] * sm[k] + sr[k] * sr[k];
        if (v > 0 && vr[k] > 0) { c[s] += d * d / v; nb[s]++; c["all"] += d * d / v; nb["all"]++ }
        if (!(s in seen)) { seen[s] = 1; names[++ns] = s }
    }
    names[++ns] = "all";
    printf "%-6s %6s %10s %8s %10s %10s\n", "surf", "bins", "chi2", "z", "rel_rms", "max_rel";
    for (i = 1; i <= ns; i++) {
        s = names[i];
        rel = rr[s] > 0 ? sqrt(dd[s] / rr[s]) : 0;
        if (nb[s] > 0)
            printf "%-6s %6d %10.1f %8.2f %10.3g %10.3g\n", s, nb[s], c[s],
                   (c[s] - nb[s]) / sqrt(2 * nb[s]), rel, mx[s];
        else
            printf "%-6s %6s %10s %8s %10.3g %10.3g\n", s, "-", "-", "-", rel, mx[s];
    }
}
