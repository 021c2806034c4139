#!/bin/sh
# GRASS r.sunmask side by side with relume-bake shadow.
#
# Crops a 512x512 window of the bundled SRTM DEM (UTM 11N, 30 m), runs GRASS's r.sunmask and
# relume's three hard-shadow methods on it for one sun, and prints the times, their ratio, and
# the pixels where the masks differ. Optional: without GRASS (`apt-get install grass-core
# gdal-bin`, `pip install rasterio`) it says so and exits 0.
#
#   scripts/grass/sunmask_compare.sh [AZIMUTH] [ELEVATION]     (default 135 30)
set -eu
AZ=${1:-135}
EL=${2:-30}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BAKE=${RELUME_BAKE:-$ROOT/target/release/relume-bake}
for tool in grass gdal_translate python3; do
  command -v $tool >/dev/null 2>&1 || { echo "SKIP: $tool is missing (apt-get install grass-core gdal-bin)"; exit 0; }
done
python3 -c "import rasterio" 2>/dev/null || { echo "SKIP: python3 rasterio is missing (pip install rasterio)"; exit 0; }
[ -x "$BAKE" ] || (cd "$ROOT" && cargo build --release --locked --bin relume-bake)
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
gdal_translate -q -srcwin 300 60 512 512 "$ROOT/scenes/dem/srtm_bigtujunga_30m.tif" "$W/crop.tif"
cd "$W"
grass --tmp-location EPSG:32611 --exec sh -c "r.in.gdal --quiet input=crop.tif output=dem && g.region raster=dem && \
  /usr/bin/time -f '%e' -o grass.seconds r.sunmask --quiet elevation=dem output=mask altitude=$EL azimuth=$AZ && \
  r.out.gdal --quiet input=mask output=grass.tif" >/dev/null 2>&1
for m in sweep accelerated exact; do
  "$BAKE" shadow crop.tif --sun-azimuth "$AZ" --sun-elevation "$EL" --method $m --out relume-$m.tif --json > relume-$m.json
done
python3 - "$AZ" "$EL" <<'PY'
import json, sys, rasterio
az, el = sys.argv[1:3]
g = rasterio.open("grass.tif").read(1, masked=True)
grass = ~g.mask & (g.data == 1)          # r.sunmask: 1 = shadow, null = lit
tg = float(open("grass.seconds").read().split()[-1])
print(f"## r.sunmask vs relume-bake shadow: SRTM Big Tujunga 512x512 (30 m), sun {az}°/{el}°\n")
print("| method | seconds | GRASS / method | shadowed | differing from GRASS | GRASS only | relume only |")
print("|---|---|---|---|---|---|---|")
print(f"| GRASS r.sunmask | {tg:.2f} | 1 | {grass.mean()*100:.2f} % | — | — | — |")
for m in ["sweep", "accelerated", "exact"]:
    r = rasterio.open(f"relume-{m}.tif").read(1) == 0
    t = json.load(open(f"relume-{m}.json"))["seconds"]
    print(f"| relume {m} | {t:.3f} | {tg/t:,.0f}x | {r.mean()*100:.2f} % | {(grass != r).sum()} | {(grass & ~r).sum()} | {(r & ~grass).sum()} |")
PY
