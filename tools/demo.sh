#!/usr/bin/env bash
# The README's main command: yarnhom's pipeline on built-in defaults, printing where each
# artifact went: published and generated patterns, the Table 4.1 yarn models, inspection,
# conversion (JSON, HDF5, .pyp), periodic tile solves, a rest-state relaxation, a reduced
# sampling sweep, the spline fit, a drape simulation recorded as an MCAP trace, the published
# ARCSim-HYLC material imported and simulated, the trace filters, rerun and HDF5 exports of a
# trace, a tile solve traced iteration by iteration, and semantic diff.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
out="${1:-demo-out}"
data="../shared/data/hylc-patterns"
mkdir -p "$out"
cargo build --quiet -p yarnhom-cli
yarnhom() { cargo run --quiet -p yarnhom-cli -- "$@"; }

echo "== published rib pattern (HYLC) -> $out/rib.pattern.yh"
yarnhom pattern import "$data/rib.pyp" -o "$out/rib.pattern.yh"
yarnhom inspect "$out/rib.pattern.yh"

echo "== built-in generators -> $out/<name>.pattern.yh"
yarnhom pattern list
for name in stockinette garter rib seed plain basket satin; do
  yarnhom pattern generate "$name" -o "$out/gen-$name.pattern.yh"
done

echo "== yarn models of Table 4.1 -> $out/<row>.yarnmodel.yh"
yarnhom model write table4.1:rib -o "$out/rib.yarnmodel.yh"
yarnhom inspect "$out/rib.yarnmodel.yh"

echo "== conversions of the rib pattern"
yarnhom convert "$out/rib.pattern.yh" --to json -o "$out/rib.pattern.json"
yarnhom convert "$out/rib.pattern.yh" --to hdf5 -o "$out/rib.pattern.h5"
yarnhom convert "$out/rib.pattern.yh" --to pyp -o "$out/rib.pyp"

echo "== periodic tile solve: the published stockinette stretched 30% along X1 -> $out/stock-sx0.3.rvesolve.yh"
yarnhom rve solve "$data/stock.pyp" --model table4.1:stock --strain sx=0.3 -o "$out/stock-sx0.3.rvesolve.yh"

echo "== rest state (Algorithm 2): the generated stockinette relaxed with the Table 4.1 stock yarn -> $out/gen-stockinette.relaxed.pattern.yh"
yarnhom rve relax "$out/gen-stockinette.pattern.yh" --model table4.1:stock -o "$out/gen-stockinette.relaxed.pattern.yh"
yarnhom rve solve "$out/gen-stockinette.relaxed.pattern.yh" --model table4.1:stock --strain sx=0.2 \
  -o "$out/gen-stockinette-sx0.2.rvesolve.yh"

echo "== sampling sweep (App. A.3.1, reduced plan: 11 values per 1D term, 5 x 5 per 2D term) -> $out/gen-stockinette.grid.yh"
yarnhom rve sample "$out/gen-stockinette.relaxed.pattern.yh" --model table4.1:stock --n1d 11 --n2d 5 \
  -o "$out/gen-stockinette.grid.yh"
yarnhom convert "$out/gen-stockinette.grid.yh" --to hdf5 -o "$out/gen-stockinette.grid.h5"

echo "== spline fit (Algorithms 3-5) -> $out/gen-stockinette.spline.yh, figures in $out/fit-figures/"
yarnhom fit "$out/gen-stockinette.grid.yh" --stockinette -o "$out/gen-stockinette.spline.yh"
yarnhom fit plot "$out/gen-stockinette.grid.yh" "$out/gen-stockinette.spline.yh" -o "$out/fit-figures"
yarnhom fit export-arcsim "$out/gen-stockinette.spline.yh" -o "$out/gen-stockinette.arcsim.json"

echo "== drape of our fitted stockinette over a sphere (coarse mesh, 0.5 s) -> $out/drape.mcap"
yarnhom shell simulate drape --material "$out/gen-stockinette.spline.yh" --resolution 15 --steps-per-frame 1 \
  --frames 30 -o "$out/drape.mcap" --obj-dir "$out/drape-obj"

echo "== the published stockinette material (ARCSim-HYLC stock1.json) stretched along x -> $out/stock1-stretch-x.mcap"
yarnhom fit import-arcsim ../shared/data/hylc-materials/stock1.json -o "$out/stock1.spline.yh"
yarnhom fit compare "$out/stock1.spline.yh" "$out/gen-stockinette.spline.yh"
yarnhom shell simulate stretch-x --material "$out/stock1.spline.yh" --resolution 15 --steps-per-frame 1 \
  --frames 30 -o "$out/stock1-stretch-x.mcap"

echo "== trace filters: the drape decimated through a pipe, summarized, exported for training -> $out/drape-every3.mcap, $out/drape.h5, $out/drape.rrd"
yarnhom trace decimate "$out/drape.mcap" --every 3 -o - | yarnhom trace select --topic '/mesh/*' -o "$out/drape-every3.mcap"
yarnhom trace info "$out/drape-every3.mcap"
yarnhom trace export "$out/drape.mcap" --format hdf5 -o "$out/drape.h5"
yarnhom rerun "$out/drape.mcap" --save "$out/drape.rrd"

echo "== a tile solve recorded iteration by iteration -> $out/stock-solve.mcap"
yarnhom rve solve "$data/stock.pyp" --model table4.1:stock --strain sx=0.1 \
  --trace "$out/stock-solve.mcap" -o "$out/stock-sx0.1.rvesolve.yh"
yarnhom trace info "$out/stock-solve.mcap"

echo "== semantic diff: the HDF5 export against the original (equal), stockinette against rib (different), our fit against the published stock1 (different)"
yarnhom diff "$out/rib.pattern.yh" "$out/rib.pattern.h5"
if yarnhom diff "$out/gen-stockinette.pattern.yh" "$out/gen-rib.pattern.yh" >/dev/null; then
  echo "unexpected: different patterns compared equal" >&2
  exit 1
fi
status=0
yarnhom diff "$out/stock1.spline.yh" "$out/gen-stockinette.spline.yh" --rtol 0.05 || status=$?
if [ "$status" -ne 1 ]; then
  echo "unexpected: diff of two different materials exited $status" >&2
  exit 1
fi
echo "== calibration (Ch. 6): the real acrylic seed swatch (stitch-by-stitch) -> $out/seed/, shell fit in $out/seed-fit/, diagnosis in $out/seed-diagnosis/"
sbs=../shared/data/stitch-by-stitch-acrylic
yarnhom measure import-stitch-by-stitch "$sbs/acrylic-seed-x.h5" "$sbs/acrylic-seed-y.h5" -o "$out/seed" --every 4
yarnhom measure check "$out/seed"
yarnhom calibrate shell "$out/seed" -o "$out/seed-fit" --spacing 0.006
yarnhom calibrate diagnose "$out/seed" -o "$out/seed-diagnosis" --budget quick
echo "== done: artifacts in $out/"
