# plot_style.gp: the one place that fixes how ppbench's plots look (reference: Outputs), loaded
# by scripts/plots.sh and by the sweep heat maps (src/drivers/sweep_plot.c).
#   mcolor(m)  a method's colour, the same in every plot (Okabe-Ito, then Paul Tol's muted
#              scheme: colour-blind safe; the Monte Carlo references black); an unknown
#              method grey.
#   palettes   viridis (perceptual, for magnitudes: heat maps) and the error images' diverging
#              map blue .. light grey .. red (Moreland's cool-warm stops, as src/io/images.c
#              draws the error maps, linear between the stops in sRGB).
mcolor(m) = m eq 'mc' ? '#000000' : m eq 'mc1' ? '#7f7f7f' : m eq 'pp' ? '#0072B2' : \
            m eq 'ss' ? '#009E73' : m eq 'mp' ? '#D55E00' : m eq 'mp+ss' ? '#CC79A7' : \
            m eq 'rte2d' ? '#E69F00' : m eq 'burley' ? '#882255' : \
            m eq 'burley+ss' ? '#CC6677' : m eq 'bdipole' ? '#332288' : \
            m eq 'bdipole+ss' ? '#88CCEE' : m eq 'dirpole' ? '#999933' : \
            m eq 'dirpole+ss' ? '#DDCC77' : m eq 'pbd' ? '#AA4499' : \
            m eq 'external' ? '#56B4E9' : '#999999'
mpoint(m) = m eq 'mc' ? 7 : m eq 'mc1' ? 6 : m eq 'pp' ? 5 : m eq 'ss' ? 9 : m eq 'mp' ? 11 : \
            m eq 'mp+ss' ? 13 : m eq 'rte2d' ? 4 : m eq 'burley' ? 8 : m eq 'burley+ss' ? 10 : \
            m eq 'bdipole' ? 12 : m eq 'bdipole+ss' ? 14 : m eq 'dirpole' ? 2 : \
            m eq 'dirpole+ss' ? 3 : m eq 'pbd' ? 15 : 1
viridis = "set palette defined (0 '#440154', 1 '#482878', 2 '#3E4989', 3 '#31688E', \
  4 '#26828E', 5 '#1F9E89', 6 '#35B779', 7 '#6DCD59', 8 '#B4DE2C', 9 '#FDE725')"
coolwarm = "set palette defined (-50 '#3B4CC0', 0 '#DDDDDD', 50 '#B40426')"
