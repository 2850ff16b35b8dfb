# searchlight_plot.gp: the searchlight study's figure (scripts/searchlight_study.sh sets DIR,
# ALBEDOS, DMAX and loads plot_style.gp first). One panel per albedo: S1's exitance per unit
# line strength against the distance from the line, log y, the Monte Carlo with its standard
# errors beside each model; the last panel Burley's s refit beside Christensen & Burley's Eq. 5.
set terminal pngcairo size 1500,960 font 'Sans,11'
set output DIR.'/searchlight.png'
set datafile separator ','
set multiplot layout 2,3 title 'Line searchlight, normal light, g = 0, n = 1: exitance of S1 against distance from the line' font 'Sans,13'
models = 'burley bdipole dirpole pbd mp'
col(m) = m eq 'burley' ? 6 : m eq 'bdipole' ? 7 : m eq 'dirpole' ? 8 : m eq 'pbd' ? 9 : 10
set logscale y
set format y '10^{%T}'
set xrange [0:DMAX]
set xlabel 'distance from the line (mfp)'
set ylabel 'exitance per unit line strength (1/mfp)'
set grid lc rgb '#dddddd'
set mytics 10
do for [i=1:words(ALBEDOS)] {
    a = word(ALBEDOS, i)
    f = DIR.'/profile_a'.a.'.csv'
    set title 'albedo '.a
    if (i == 1) { set key top right font 'Sans,10' } else { unset key }
    # y from the Monte Carlo inside the window (autoscale would follow the far tail and the
    # error bars that reach 0)
    stats f every ::1 using ($1 <= DMAX ? $4 : NaN) nooutput
    set yrange [STATS_min / 4 : STATS_max * 4]
    plot f every ::1 using 1:4:5 with yerrorbars pt 7 ps 0.35 lc rgb mcolor('mc') title 'mc (1 s.e.)', \
         for [m in models] f every ::1 using 1:(column(col(m))) with lines lw 2 lc rgb mcolor(m) title m
}
unset logscale y
set format y '%g'
unset mytics
set yrange [*:*]
set title "Burley's s (mfp) refit to mc: A = mc's R"
set xlabel 'A (total diffuse reflectance)'
set ylabel 's x mfp'
set xrange [0:1]
set yrange [0:*]
set key top right font 'Sans,10'
eq5(x) = 1.85 - x + 7 * abs(x - 0.8)**3
plot eq5(x) with lines lw 2 lc rgb mcolor('burley') title 'Eq. 5: 1.85 - A + 7|A - 0.8|^3', \
     DIR.'/burley_fit.csv' every ::1 using 2:4 with points pt 7 ps 1.3 lc rgb 'black' title 'least-squares fit'
unset multiplot

# The same profiles as model / mc (log y), the Monte Carlo's 1 s.e. as error bars about 1.
set output DIR.'/searchlight_ratio.png'
set multiplot layout 2,3 title 'Line searchlight, normal light, g = 0, n = 1: model / mc of S1''s exitance' font 'Sans,13'
set logscale y
set yrange [0.2:5]
set ytics (0.2, 0.3, 0.5, 0.7, 1, 1.5, 2, 3, 5)
set format y '%g'
set xrange [0:DMAX]
set xlabel 'distance from the line (mfp)'
set ylabel 'model / mc'
do for [i=1:words(ALBEDOS)] {
    a = word(ALBEDOS, i)
    f = DIR.'/profile_a'.a.'.csv'
    set title 'albedo '.a
    if (i == 1) { set key bottom left font 'Sans,10' } else { unset key }
    plot f every ::1 using 1:(1):($5 / $4) with yerrorbars pt 7 ps 0.2 lc rgb mcolor('mc') title 'mc (1 s.e.)', \
         for [m in models] f every ::1 using 1:(column(col(m)) / $4) with lines lw 2 lc rgb mcolor(m) title m
}
unset multiplot
