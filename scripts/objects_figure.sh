#!/usr/bin/env bash
# objects_figure.sh DIR NAME: DIR/figure.png from one `ppbench object` set (objects_study.sh):
# top row the images of mc3d (the reference), ss3d and pp3d on one exposure, bottom row the error
# images (method - mc3d), each with its colour bar. The PNGs are decoded back to the values the
# driver encoded (docs/reference.md, Objects, Outputs): a grey pixel is sRGB(L / L_max) with
# L_max the reference's brightest pixel; an error pixel is white at 0, full red (blue) at +10 %
# (-10 %) of L_max, its green channel 255 (1 - |x| / 0.1).
set -euo pipefail
dir=$1
name=$2
img=$dir/images
gnuplot <<EOF
set terminal pngcairo size 1050,640 font "sans,10"
set output "$dir/figure.png"
lin(s) = s <= 0.04045 ? s / 12.92 : ((s + 0.055) / 1.055) ** 2.4
srgb(x) = x <= 0.0031308 ? 12.92 * x : 1.055 * x ** (1 / 2.4) - 0.055
err(r, g, b) = (r >= b ? 1 : -1) * (1 - g / 255.0) * 0.1
set multiplot layout 2,3 title "$name: images on one exposure (L_{max}: mc3d's brightest pixel), errors against mc3d (clamped at 0.1 L_{max})"
unset xtics; unset ytics; unset key
set size ratio -1
set yrange [*:*] reverse
set palette functions srgb(gray), srgb(gray), srgb(gray)
set cbrange [0:1]
set cblabel "L / L_{max}"
do for [m in "mc3d ss3d pp3d"] {
  set title m.(m eq "mc3d" ? " (reference)" : "")
  plot "$img/".m.".png" binary filetype=png using (lin(\$1 / 255.0)) with image
}
set multiplot next
set palette defined (-0.1 "blue", 0 "white", 0.1 "red")
set cbrange [-0.1:0.1]
set cblabel "(L - L_{mc3d}) / L_{max}"
set title "ss3d - mc3d"
plot "$img/ss3d_error.png" binary filetype=png using (err(\$1, \$2, \$3)) with image
set title "pp3d - mc3d"
plot "$img/pp3d_error.png" binary filetype=png using (err(\$1, \$2, \$3)) with image
unset multiplot
EOF
