#!/usr/bin/env bash
# Fig 4.8 of the dissertation: texel density of visibility-aware maps
# relative to the plain (isometric) map, for every view model optimized for
# (columns) and measured under (rows), on the four synthetic shapes of fig
# 4.4 (bench/shapes.c) and on the cow and the camel of tests/data.
#
#   bash bench/fig48.sh > fig48.md          (about 2 minutes on 2 cores)
#
# Builds build/bench/shapes and build/bench/fig48 (bench/fig48.c, one map
# per column computed once, every row measured with bp_texture_to_screen),
# writes the shapes into build/shapes/ and prints one markdown section per
# mesh.  Entry = isometric_det / map_det, as `build/bijparam MESH
# --visibility COL --density-report ROW --json` reports in density.ratio.
#
# View directions (directions toward the camera):
#   synthetic shapes (axis +y; the cup opens toward +y):
#       front +z, side +x, ring about +y at 30 degrees
#   cow (up +y, head toward +x, flank toward +z):
#       front +x (the head), side +z (the flank), ring about +y at 30 degrees
#   camel_b (up +y, head toward +z, flank toward +x):
#       front +z (the head), side +x (the flank), ring about +y at 30 degrees
# Environment: FIG48_SAMPLES (rays per triangle for the optimized maps,
# default 64 = the tool's default), FIG48_MEASURE (rays per triangle for the
# measurement, default 256), FIG48_FLOOR (default 0.05), CC, CPPFLAGS.
set -eu
cd "$(dirname "$0")/.."
cc=${CC:-cc}
flags="-std=c99 -O2 -Wall -Wextra -pedantic -Werror"
mkdir -p build/bench build/shapes
$cc $flags bench/shapes.c -o build/bench/shapes -lm
$cc $flags ${CPPFLAGS:--I.} -DBP_USE_PTHREADS -pthread bench/fig48.c -o build/bench/fig48 -lm
build/bench/shapes build/shapes 2>/dev/null
common="--samples ${FIG48_SAMPLES:-64} --measure-samples ${FIG48_MEASURE:-256} --floor ${FIG48_FLOOR:-0.05} --up 0,1,0 --elevation 30"
run() { build/bench/fig48 "$@" $common 2>/dev/null; }
run build/shapes/cup.obj cup --front 0,0,1 --side 1,0,0
run build/shapes/holes.obj holes --front 0,0,1 --side 1,0,0
run build/shapes/ripple.obj ripple --front 0,0,1 --side 1,0,0
run build/shapes/sphere.obj sphere --front 0,0,1 --side 1,0,0
run tests/data/cow_param_withSUV.obj cow --front 1,0,0 --side 0,0,1
run tests/data/camel_b.obj camel_b --front 0,0,1 --side 1,0,0
