#!/usr/bin/awk -f
# totals_z.awk: a method's per-surface totals against the Monte Carlo's, in its standard errors.
#
#   awk -F, -v m=rte2d [-v rel=1] -f scripts/totals_z.awk DIR/mc_totals.csv DIR/totals.csv
#
# For R, T and sides: z = (m's total in totals.csv - mc's mean) / mc's se (mc_totals.csv,
# docs/reference.md, Outputs), printed comma-separated in that order; "-" where mc has no
# standard error. rel=1: the relative differences (m - mc) / mc in % instead ("-" where mc's
# total is 0). A deterministic method that is exact gives normal deviates (t-distributed on
# batches - 1 degrees of freedom).
BEGIN {
    FS = ",";
    if (m == "") {
        print "totals_z: give the method: -v m=ID" > "/dev/stderr";
        exit 2;
    }
}
FNR == 1 { nfile++; next }
nfile == 1 && $1 == "mc" { mean[$2] = $3; se[$2] = $4 }
nfile == 2 && $1 == m { got["R"] = $2; got["T"] = $3; got["sides"] = $4; seen = 1 }
END {
    if (!seen) { print "totals_z: no totals row of method " m > "/dev/stderr"; exit 2 }
    n = split("R T sides", q, " ");
    for (i = 1; i <= n; i++) {
        k = q[i];
        sep = i > 1 ? "," : "";
        if (rel && mean[k] != 0) printf "%s%.3g", sep, 100 * (got[k] - mean[k]) / mean[k];
        else if (!rel && se[k] > 0) printf "%s%.3g", sep, (got[k] - mean[k]) / se[k];
        else printf "%s-", sep;
    }
    printf "\n";
}
