#!/usr/bin/awk -f
# surface_totals.awk: a method's per-surface totals against the Monte Carlo's, for R (S1), T
# (S2) and sides (S3 + S4), printed comma-separated in that order ("-" where there is nothing to
# compare).
#
#   awk -v m=rte2d -f scripts/surface_totals.awk DIR/mc_totals.csv DIR/totals.csv
#       z = (m's total in totals.csv - mc's mean) / mc's se (mc_totals.csv, docs/reference.md,
#       Outputs): an exact deterministic method gives normal deviates (t-distributed on
#       batches - 1 degrees of freedom); "-" where mc has no standard error;
#   awk -v m=rte2d -v rel=1 -f scripts/surface_totals.awk DIR/mc_totals.csv DIR/totals.csv
#       the relative differences (m - mc) / mc in %; "-" where mc's total is 0;
#   awk -v m=rte2d -v bins=1 -f scripts/surface_totals.awk DIR/radiance.csv
#       the same from the exit radiance: both methods hold the same (segment, bin) cells and a
#       cell's energy is its radiance times a measure that depends on the surface alone, so the
#       ratio of the radiance sums over a surface is the ratio of the integrated fluxes; in %.
BEGIN {
    FS = ",";
    if (m == "") {
        print "surface_totals: give the method: -v m=ID" > "/dev/stderr";
        exit 2;
    }
    nq = split("R T sides", q, " ");
}
FNR == 1 { nfile++; next }
bins && ($1 == m || $1 == "mc") {
    k = ($2 == "S3" || $2 == "S4") ? "sides" : ($2 == "S1" ? "R" : ($2 == "S2" ? "T" : ""));
    if (k == "") next;
    if ($1 == m) { got[k] += $7; seen = 1 } else { mean[k] += $7; se[k] = 1 }
    next;
}
!bins && nfile == 1 && $1 == "mc" { mean[$2] = $3; se[$2] = $4 }
!bins && nfile == 2 && $1 == m { got["R"] = $2; got["T"] = $3; got["sides"] = $4; seen = 1 }
END {
    if (!seen) { print "surface_totals: no rows of method " m > "/dev/stderr"; exit 2 }
    for (i = 1; i <= nq; i++) {
        k = q[i];
        sep = i > 1 ? "," : "";
        if ((rel || bins) && mean[k] != 0) printf "%s%.3g", sep, 100 * (got[k] - mean[k]) / mean[k];
        else if (!rel && !bins && se[k] > 0) printf "%s%.3g", sep, (got[k] - mean[k]) / se[k];
        else printf "%s-", sep;
    }
    printf "\n";
}
