#!/usr/bin/env python3
"""Exit status, peak memory and wall time of `glint` on the hostile inputs of the second round
(issue 55), one line each, so that two binaries can be compared side by side:

    scripts/hostile-figures.py GLINT [--cap-mb N] [--only NAME,...]

Every run is capped at --cap-mb of address space (default 3072) and 30 s, so an old binary
cannot take the machine; a run still going at the limit is reported as "hang". The inputs are
made in a temporary folder; nothing else is written. Standard library only.
"""

import argparse
import os
import resource
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

CAMERA = (
    '<camera type="perspective"><position>0 0 0</position><viewDir>0 0 -1</viewDir>'
    "<focalLength>1</focalLength><imagePlaneWidth>1</imagePlaneWidth></camera>"
    '<light type="point"><position>0 3 0</position><intensity>1 1 1</intensity></light>\n'
)
SHADER = '<shader name="b" type="Lambertian"><diffuse>1 1 1</diffuse></shader>\n'
SPHERE = '<shape type="sphere"><shader ref="b"/><center>0 0 -5</center><radius>1</radius></shape>\n'


def chunk(kind, data):
    body = kind + data
    return (
        struct.pack(">I", len(data))
        + body
        + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    )


def blank_png(side):
    """A black RGB PNG of side x side pixels, a few hundred KB compressed."""
    row = b"\x00" * (side * 3 + 1)
    compressor = zlib.compressobj(9)
    data = b"".join(compressor.compress(row) for _ in range(side)) + compressor.flush()
    header = struct.pack(">IIBBBBB", side, side, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", data)
        + chunk(b"IEND", b"")
    )


def exr_attribute(data, name):
    """Offset of the value of header attribute `name` of an EXR file."""
    key = name.encode() + b"\x00box2i\x00"
    at = data.index(key) + len(key)
    assert struct.unpack("<i", data[at : at + 4])[0] == 16
    return at + 4


def with_window(data, name, box):
    at = exr_attribute(data, name)
    return data[:at] + struct.pack("<4i", *box) + data[at + 16 :]


def write(path, text):
    mode = "wb" if isinstance(text, bytes) else "w"
    with open(path, mode) as f:
        f.write(text)


def scene(body):
    return "<scene>\n" + CAMERA + SHADER + body + "</scene>\n"


class Case:
    def __init__(
        self, name, args, setup=None, signal_after=None, check=None, limit=30.0
    ):
        self.name, self.args, self.setup = name, args, setup
        self.signal_after, self.check, self.limit = signal_after, check, limit


def run(glint, case, cap_mb, work):
    for entry in os.listdir(work):
        if entry.startswith(("out", ".glint-")):
            os.remove(os.path.join(work, entry))
    if case.setup:
        case.setup(work)

    def limit():
        cap = cap_mb << 20
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        os.setsid()

    start = time.monotonic()
    # To a file, not a pipe: a run that prints megabytes of warnings must not block on it.
    err_file = tempfile.TemporaryFile()  # noqa: SIM115 (closed below, after the wait)
    process = subprocess.Popen(
        [glint] + case.args,
        cwd=work,
        stdout=subprocess.DEVNULL,
        stderr=err_file,
        preexec_fn=limit,  # noqa: PLW1509 (this script starts no threads)
    )
    signalled_at = None
    status = rusage = None
    while True:
        pid, raw, rusage = os.wait4(process.pid, os.WNOHANG)
        if pid:
            status = raw
            break
        now = time.monotonic() - start
        if (
            case.signal_after is not None
            and signalled_at is None
            and now >= case.signal_after
        ):
            process.send_signal(signal.SIGTERM)
            signalled_at = now
        if now > case.limit:
            os.killpg(process.pid, signal.SIGKILL)
            _, status, rusage = os.wait4(process.pid, 0)
            status = None
            break
        time.sleep(0.02)
    wall = time.monotonic() - start
    err_file.seek(0)
    err = err_file.read(1 << 20).decode(errors="replace")
    err_file.close()
    process.returncode = 0  # reaped by wait4 above
    if status is None:
        outcome = "hang"
    elif os.WIFSIGNALED(status):
        outcome = f"sig{os.WTERMSIG(status)}"
    else:
        outcome = str(os.WEXITSTATUS(status))
    rss_mb = rusage.ru_maxrss / 1024
    react = ""
    if signalled_at is not None and status is not None:
        react = f" reacted in {wall - signalled_at:.2f} s,"
    note = case.check(work) if case.check else ""
    first = next((line for line in err.splitlines() if line.strip()), "")
    return (
        f"{case.name:<22} exit {outcome:<4} RSS {rss_mb:7.0f} MB wall {wall:6.2f} s{react} "
        f"{note}| {first[:100]}"
    )


def cases(glint, work):
    write(os.path.join(work, "small.xml"), scene(SPHERE))

    def exists(name):
        return lambda w: (
            f"{name} {'kept' if os.path.exists(os.path.join(w, name)) else 'GONE'} "
        )

    def part(w, name, args):
        subprocess.run(
            [
                glint,
                "render",
                "small.xml",
                "-w",
                "8",
                "-h",
                "8",
                "--integrator",
                "path",
                "-r",
                "4",
                "-o",
                name,
            ]
            + args,
            cwd=w,
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

    def parts(w):
        part(w, "p0.exr", ["--sample-range", "0/2"])
        part(w, "p1.exr", ["--sample-range", "1/2"])
        with open(os.path.join(w, "p1.exr"), "rb") as f:
            data = f.read()
        # The data window moved 4 pixels right: half of it outside the 8x8 display window.
        write(
            os.path.join(w, "shifted.exr"),
            with_window(data, "dataWindow", (4, 0, 11, 7)),
        )
        huge = with_window(
            with_window(data, "displayWindow", (0, 0, 119999, 119999)),
            "dataWindow",
            (0, 0, 119999, 119999),
        )
        write(os.path.join(w, "huge.exr"), huge[:1024])

    def poster(w):
        # Genuine parts of a 65535 x 65535 poster: 8 x 8 pixels each, two sample ranges.
        for i in range(2):
            subprocess.run(
                [
                    glint,
                    "render",
                    "small.xml",
                    "-w",
                    "65535",
                    "-h",
                    "65535",
                    "--pixel-bounds",
                    "0,8,0,8",
                    "--integrator",
                    "path",
                    "-r",
                    "2",
                    "--sample-range",
                    f"{i}/2",
                    "--max-memory",
                    "1T",
                    "-o",
                    f"q{i}.exr",
                ],
                cwd=w,
                check=True,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )

    def diff_pngs(w):
        png = blank_png(9000)
        write(os.path.join(w, "a.png"), png)
        write(os.path.join(w, "b.png"), png)

    def long_names(w):
        a, b = "a" * 20000, "b" * 20000
        write(
            os.path.join(w, "names.xml"),
            scene(
                f'<shader name="{a}" type="Lambertian"><diffuse>1 1 1</diffuse></shader>'
                f'<shape type="sphere"><shader ref="{b}"/><center>0 0 -5</center><radius>1</radius>'
                "</shape>\n"
            ),
        )

    def one_line(w):
        keys = "".join(f'"k{i}": "xxxxxxxxxxxxxxxxxxxx", ' for i in range(110000))
        write(
            os.path.join(w, "line.json"),
            '{"scene": {"note": "\u00e9", '
            + keys
            + '"camera": [{"_type": "perspective", '
            '"position": "0 0 0", "viewDir": "0 0 -1", "focalLength": 1, "imagePlaneWidth": '
            '0.5}], "shader": [{"_name": "b", "_type": "Lambertian", "diffuse": "0 0 1"}], '
            '"shape": [{"_type": "sphere", "shader": {"_ref": "b"}, "center": "0 0 -5", '
            '"radius": 1}]}}',
        )

    def fifo(w):
        path = os.path.join(w, "pipe.obj")
        if not os.path.exists(path):
            os.mkfifo(path)
        write(
            os.path.join(w, "fifo.xml"),
            scene(
                '<instance name="m" type="mesh"><file>pipe.obj</file><shader ref="b"/></instance>'
                '<shape type="instance" id="m"/>\n'
            ),
        )

    def glass(w):
        slabs = "".join(
            f'<shape type="box"><shader ref="g"/><minPt>-2 -2 {-3 - i:g}</minPt>'
            f"<maxPt>2 2 {-2.9 - i:g}</maxPt></shape>\n"
            for i in range(4)
        )
        write(
            os.path.join(w, "glass.xml"),
            scene(
                '<shader name="g" type="Dielectric"><refractiveIndex>1.5</refractiveIndex>'
                "<attenuation>1 1 1</attenuation></shader>" + slabs + SPHERE
            ),
        )

    def empties(w):
        write(
            os.path.join(w, "empty.xml"),
            "<scene>\n" + CAMERA + SHADER + SPHERE + "<x/>" * 10_000_000 + "</scene>\n",
        )

    def array(w):
        write(
            os.path.join(w, "array.json"),
            '{"scene": {"camera": [{"_type": "perspective", "position": "0 0 0", "viewDir": '
            '"0 0 -1", "focalLength": 1, "imagePlaneWidth": 0.5}], "junk": ['
            + "0," * 15_000_000
            + "0]}}",
        )

    def instances(w):
        body = (
            '<instance name="s" type="sphere"><shader ref="b"/><center>0 0 0</center>'
            "<radius>0.001</radius></instance>\n"
            + '<shape type="instance" id="s"><transform><translate>0 0 -5</translate>'
            "</transform></shape>\n" * 1_000_000
        )
        write(os.path.join(w, "instances.xml"), scene(body))

    def big_face(w):
        corners = 19_000_000
        with open(os.path.join(w, "face.obj"), "w") as f:
            f.write("v 0 0 -5\nv 1 0 -5\nv 0 1 -5\nf")
            f.write(" 1 2 3" * (corners // 3))
            f.write("\n")
        write(
            os.path.join(w, "face.xml"),
            scene(
                '<instance name="m" type="mesh"><file>face.obj</file><shader ref="b"/></instance>'
                '<shape type="instance" id="m"/>\n'
            ),
        )

    def textures(w):
        png = blank_png(8192)
        for i in range(3):
            write(os.path.join(w, f"t8k{i}.png"), png)
        body = "".join(
            f'<texture name="t{i}" type="image"><sourcefile>t8k{i}.png</sourcefile></texture>'
            f'<shader name="s{i}" type="Lambertian"><diffuse tex="t{i}">1 1 1</diffuse></shader>\n'
            f'<shape type="sphere"><shader ref="s{i}"/><center>{i - 1} 0 -5</center><radius>0.5'
            "</radius></shape>\n"
            for i in range(3)
        )
        write(os.path.join(w, "tex.xml"), scene(body))

    def identical(w):
        with open(os.path.join(w, "same.obj"), "w") as f:
            f.write("v -1 -1 -5\nv 1 -1 -5\nv 0 1 -5\n" + "f 1 2 3\n" * 1_000_000)
        write(
            os.path.join(w, "same.xml"),
            scene(
                '<instance name="m" type="mesh"><file>same.obj</file><shader ref="b"/></instance>'
                '<shape type="instance" id="m"/>\n'
            ),
        )

    def merge_partial(w):
        # A stale partial file from a merge killed while writing.
        parts(w)
        stale = os.path.join(w, ".glint-999999-stale.partial")
        write(stale, b"x")
        # An hour old: left by a run before this one (a newer file may be a live writer's).
        os.utime(stale, (time.time() - 3600, time.time() - 3600))

    def partial_left(w):
        names = [n for n in os.listdir(w) if n.endswith(".partial")]
        return f"partials {len(names)} "

    return [
        Case(
            "checkpoint = -o",
            [
                "render",
                "small.xml",
                "-w",
                "16",
                "-h",
                "16",
                "-o",
                "out.exr",
                "--checkpoint",
                "./out.exr",
            ],
            setup=lambda w: write(os.path.join(w, "out.exr"), b"an earlier image"),
            check=exists("out.exr"),
        ),
        Case(
            "progress 1e20",
            [
                "render",
                "small.xml",
                "-w",
                "8",
                "-h",
                "8",
                "-o",
                "out.png",
                "--progress-every",
                "1e20",
            ],
        ),
        Case(
            "checkpoint-every 1e300",
            [
                "render",
                "small.xml",
                "-w",
                "8",
                "-h",
                "8",
                "-o",
                "out.png",
                "--checkpoint",
                "ck.exr",
                "--checkpoint-every",
                "1e300",
            ],
        ),
        Case(
            "merge data > display",
            ["merge", "-o", "out.exr", "p0.exr", "shifted.exr"],
            setup=parts,
        ),
        Case(
            "merge 65535^2 poster",
            ["merge", "-o", "out.exr", "q0.exr", "q1.exr"],
            setup=poster,
        ),
        Case(
            "merge 120000^2 header",
            ["merge", "-o", "out.exr", "p0.exr", "huge.exr"],
            setup=parts,
        ),
        Case(
            "resume 120000^2",
            [
                "render",
                "small.xml",
                "-w",
                "8",
                "-h",
                "8",
                "-o",
                "out.png",
                "--resume",
                "huge.exr",
            ],
            setup=parts,
        ),
        Case("diff 9000^2 PNGs", ["diff", "a.png", "b.png"], setup=diff_pngs),
        Case("did-you-mean 20k", ["check", "names.xml"], setup=long_names),
        Case("4 MB line, 1 non-ASCII", ["check", "line.json"], setup=one_line),
        Case(
            "FIFO mesh",
            ["render", "fifo.xml", "-w", "8", "-h", "8", "-o", "out.png"],
            setup=fifo,
            limit=10,
        ),
        Case(
            "SIGTERM in -r 1e7",
            [
                "render",
                "small.xml",
                "-w",
                "2",
                "-h",
                "2",
                "-r",
                "10000000",
                "--integrator",
                "path",
                "-o",
                "out.png",
            ],
            signal_after=2.0,
        ),
        Case(
            "-r 1e9",
            [
                "render",
                "small.xml",
                "-w",
                "1",
                "-h",
                "1",
                "-r",
                "1000000000",
                "-o",
                "out.png",
            ],
            limit=10,
        ),
        Case(
            "glass -k 24",
            ["render", "glass.xml", "-w", "4", "-h", "4", "-k", "24", "-o", "out.png"],
            setup=glass,
            limit=20,
        ),
        Case("40 MB empty elements", ["check", "empty.xml"], setup=empties),
        Case("30 MB JSON array", ["check", "array.json"], setup=array),
        Case(
            "1M instances",
            ["render", "instances.xml", "-w", "8", "-h", "8", "-o", "out.png"],
            setup=instances,
        ),
        Case(
            "19M-corner face",
            ["render", "face.xml", "-w", "8", "-h", "8", "-o", "out.png"],
            setup=big_face,
        ),
        Case(
            "3 x 8192^2 PNG",
            ["render", "tex.xml", "-w", "8", "-h", "8", "-o", "out.png"],
            setup=textures,
        ),
        Case(
            "6000^2 EXR",
            ["render", "small.xml", "-w", "6000", "-h", "6000", "-o", "out.exr"],
        ),
        Case(
            "1M identical tris",
            ["render", "same.xml", "-w", "32", "-h", "32", "-o", "out.png"],
            setup=identical,
        ),
        Case(
            "-o x.png/", ["render", "small.xml", "-w", "8", "-h", "8", "-o", "x.png/"]
        ),
        Case(
            "checkpoint missing/",
            [
                "render",
                "small.xml",
                "-w",
                "8",
                "-h",
                "8",
                "-o",
                "out.png",
                "--checkpoint",
                "missing/ck.exr",
            ],
        ),
        Case(
            "merge stale partial",
            ["merge", "-o", "out.exr", "p0.exr", "p1.exr"],
            setup=merge_partial,
            check=partial_left,
        ),
    ]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("glint")
    parser.add_argument("--cap-mb", type=int, default=3072)
    parser.add_argument("--only", default="")
    args = parser.parse_args()
    glint = os.path.realpath(args.glint)
    work = tempfile.mkdtemp(prefix="glint-hostile-")
    try:
        wanted = [n for n in args.only.split(",") if n]
        for case in cases(glint, work):
            if wanted and not any(w in case.name for w in wanted):
                continue
            print(run(glint, case, args.cap_mb, work), flush=True)
    finally:
        shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
