#!/bin/sh
# Kill -9 a ~10 s render at N random moments (default 50) and count what is left: a partial
# image at the output name (a file that is not a whole PNG), and temporary files
# (.glint-*.partial) right after the kills and after one more run, which removes stale ones.
# Usage: scripts/kill-test.sh GLINT [N] [SIZE]
set -eu
glint=$(realpath "$1")
runs=${2:-50}
size=${3:-1600}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cat > scene.xml <<'XML'
<scene>
  <camera type="perspective"><position>0 0 0</position><viewDir>0 0 -1</viewDir>
    <focalLength>1</focalLength><imagePlaneWidth>0.5</imagePlaneWidth></camera>
  <light type="point"><position>0 10 0</position><intensity>1 1 1</intensity></light>
  <shader name="b" type="Lambertian"><diffuse>0 0 1</diffuse></shader>
  <shape type="sphere"><shader ref="b"/><center>0 0 -5</center><radius>1</radius></shape>
</scene>
XML
start=$(date +%s.%N)
"$glint" render scene.xml -o out.png -w "$size" -h "$size" -r 16 -n 1 2>/dev/null
full=$(echo "$(date +%s.%N) - $start" | bc)
rm -f out.png
echo "one whole render: ${full} s"
complete=0 partial=0 absent=0
i=0
while [ "$i" -lt "$runs" ]; do
    i=$((i + 1))
    # A moment between 0 and 105% of the render's length.
    delay=$(python3 -c "import random; print(round(random.uniform(0, 1.05 * $full), 3))")
    "$glint" render scene.xml -o out.png -w "$size" -h "$size" -r 16 -n 1 2>/dev/null &
    pid=$!
    sleep "$delay"
    kill -9 "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    if [ -e out.png ]; then
        # A whole PNG ends with its IEND chunk.
        if [ "$(tail -c 12 out.png | od -An -tx1 | tr -d ' \n')" = "0000000049454e44ae426082" ]; then
            complete=$((complete + 1))
        else
            partial=$((partial + 1))
        fi
        rm -f out.png
    else
        absent=$((absent + 1))
    fi
done
left=$(find . -name '.glint-*.partial' | wc -l)
"$glint" render scene.xml -o out.png -w 8 -h 8 2>/dev/null
after=$(find . -name '.glint-*.partial' | wc -l)
echo "$runs kills: $absent left no image, $complete left a whole image, $partial left a partial image"
echo "temporary files: $left right after the kills, $after after the next run"
