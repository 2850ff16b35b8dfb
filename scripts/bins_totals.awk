#!/usr/bin/awk -f
# bins_totals.awk: a method's exit radiance integrated per surface against the Monte Carlo's,
# from one radiance.csv (docs/reference.md, Outputs).
#
#   awk -F, -v m=rte2d -f scripts/bins_totals.awk DIR/radiance.csv
#
# Both hold the same (segment, bin) cells, and a cell's energy is its radiance times a measure
# that depends on the surface alone (segment length x projected solid angle, equal bins), so the
# ratio of the radiance sums over a surface is the ratio of the two integrated fluxes. Prints the
# relative differences (m - mc) / mc in % for S1 (R), S2 (T) and S3 + S4 (sides), comma-separated;
# "-" where mc has no light there (slab mode: no sides).
BEGIN {
    FS = ",";
    if (m == "") {
        print "bins_totals: give the method: -v m=ID" > "/dev/stderr";
        exit 2;
    }
}
FNR == 1 { next }
$1 == m || $1 == "mc" {
    k = ($2 == "S3" || $2 == "S4") ? "sides" : ($2 == "S1" ? "R" : ($2 == "S2" ? "T" : ""));
    if (k != "") sum[$1, k] += $7;
    if ($1 == m) seen = 1;
}
END {
    if (!seen) { print "bins_totals: no rows of method " m > "/dev/stderr"; exit 2 }
    n = split("R T sides", q, " ");
    for (i = 1; i <= n; i++) {
        k = q[i];
        sep = i > 1 ? "," : "";
        if (sum["mc", k] > 0) printf "%s%.3g", sep, 100 * (sum[m, k] - sum["mc", k]) / sum["mc", k];
        else printf "%s-", sep;
    }
    printf "\n";
}
