#!/bin/sh
# Peak memory (/usr/bin/time -v) of glint on the four memory cases of issue 9:
#   1. a 300 KB one-line JSON scene with 8,000 unused keys
#   2a. /dev/zero as the scene; 2b. an OBJ mesh that is a link to /dev/zero
#   3. -w 65535 -h 65535
#   4. three texture entries naming one 420 KB PNG that declares 12000 x 12000
#   5. 64 textures on 64 files of 8 MB each, a 1 x 1 PNG padded by an ancillary chunk (the
#      files waiting for their decode are held to 64 MiB together)
# Usage: scripts/hostile-rss.sh GLINT [CAP_KB]. Each run is capped at CAP_KB of virtual
# memory (default 6000000, ~5.7 GiB) and 120 s, so that an old binary cannot take the machine.
set -eu
glint=$(realpath "$1")
cap=${2:-6000000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
python3 - <<'PY'
import struct, zlib
def chunk(kind, data):
    body = kind + data
    return struct.pack('>I', len(data)) + body + struct.pack('>I', zlib.crc32(body) & 0xffffffff)
side = 12000
row = b'\x00' * (side * 3 + 1)
compressor = zlib.compressobj(9)
data = b''.join(compressor.compress(row) for _ in range(side)) + compressor.flush()
open('big.png', 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', side, side, 8, 2, 0, 0, 0))
                            + chunk(b'IDAT', data) + chunk(b'IEND', b''))
camera = ('<camera type="perspective"><position>0 0 0</position><viewDir>0 0 -1</viewDir>'
          '<focalLength>1</focalLength><imagePlaneWidth>1</imagePlaneWidth></camera>'
          '<light type="point"><position>0 3 0</position><intensity>1 1 1</intensity></light>\n')
keys = ''.join('"unused%d": "%s", ' % (i, 'x' * 20) for i in range(8000))
open('long.json', 'w').write(
    '{"scene": {' + keys + '"camera": [{"_type": "perspective", "position": "0 0 0", '
    '"viewDir": "0 0 -1", "focalLength": 1, "imagePlaneWidth": 0.5}], "shader": [{"_name": "b", '
    '"_type": "Lambertian", "diffuse": "0 0 1"}], "shape": [{"_type": "sphere", "shader": '
    '{"_ref": "b"}, "center": "0 0 -5", "radius": 1}]}}')
textures = ''.join('<texture name="t%d" type="image"><sourcefile>big.png</sourcefile></texture>'
                   '<shader name="s%d" type="Lambertian"><diffuse tex="t%d">1 1 1</diffuse></shader>\n'
                   % (i, i, i) for i in range(3))
spheres = ''.join('<shape type="sphere"><shader ref="s%d"/><center>%d 0 -5</center>'
                  '<radius>0.5</radius></shape>\n' % (i, i - 1) for i in range(3))
open('tex.xml', 'w').write('<scene>\n' + camera + textures + spheres + '</scene>\n')
pixel = chunk(b'IDAT', zlib.compress(b'\x00\x80\x80\x80'))
padding = chunk(b'peGz', b'\x00' * (8 << 20))
many = ''
for i in range(64):
    open('pad%d.png' % i, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 1, 1, 8, 2, 0, 0, 0))
                                    + padding + pixel + chunk(b'IEND', b''))
    many += ('<texture name="t%d" type="image"><sourcefile>pad%d.png</sourcefile></texture>'
             '<shader name="s%d" type="Lambertian"><diffuse tex="t%d">1 1 1</diffuse></shader>\n'
             % (i, i, i, i))
open('many.xml', 'w').write('<scene>\n' + camera + many + spheres.replace('s1', 's0').replace('s2', 's0')
                            + '</scene>\n')
shader = '<shader name="b" type="Lambertian"><diffuse>1 1 1</diffuse></shader>'
open('mesh.xml', 'w').write('<scene>\n' + camera + shader + '<shape type="mesh"><file>endless.obj'
                            '</file><shader ref="b"/></shape>\n</scene>\n')
open('small.xml', 'w').write('<scene>\n' + camera + shader + '<shape type="sphere"><shader ref="b"/>'
                             '<center>0 0 -5</center><radius>1</radius></shape>\n</scene>\n')
PY
ln -s /dev/zero endless.obj
measure() {
    name=$1; shift
    ( ulimit -v "$cap"; timeout 120 /usr/bin/time -v "$glint" "$@" -o out.png >out.txt 2>err.txt ) || true
    status=$(sed -n 's/.*Exit status: //p' err.txt)
    signal=$(sed -n 's/.*Command terminated by signal //p' err.txt)
    [ -z "$signal" ] || status="signal $signal"
    rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' err.txt)
    wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' err.txt)
    first=$(grep -m1 -E '^(error|warning|memory|thread)' err.txt | cut -c1-110 || true)
    printf '%-14s exit %-4s peak RSS %8s KB  wall %8s  %s\n' "$name" "$status" "${rss:-?}" "${wall:-?}" "$first"
    rm -f out.png
}
measure "1 long line" render long.json -w 8 -h 8
measure "2a /dev/zero" render /dev/zero
measure "2b OBJ zero" render mesh.xml -w 8 -h 8
measure "3 65535^2" render small.xml -w 65535 -h 65535
measure "4 12000^2 x3" render tex.xml -w 8 -h 8
measure "5 64 x 8 MB" render many.xml -w 8 -h 8
