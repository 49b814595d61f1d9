"""Contact sheet of Glint's glTF renders beside Blender/Cycles' references.

For every model of crates/io/tests/gltf_refs/manifest.json, renders it with Glint's CLI
(`glint render MODEL -o X.exr -w 160 -h 120 -r SPP --integrator path`, volpath for models
with KHR_materials_volume) and puts it beside the Cycles beauty reference: one row per model,
Glint | Cycles, labelled. Tone mapping: linear radiance clamped to [0, 1], then the sRGB
transfer function (no exposure, no curve). Writes docs/gltf-contact-sheet.png.

    python3 scripts/gltf-contact-sheet.py [--glint PATH] [--spp N] [--out FILE]

Needs numpy only (no Pillow): EXR reading and PNG writing are in scripts/blender/exr_io.py
and scripts/contact_sheet_lib.py. A model Glint fails to load or render gets a grey tile
with the error's first words.
"""

import argparse
import importlib.util
import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent


def load_module(name, path):
    """A helper module of scripts/ by its path (no sys.path changes, no late imports)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


sheet = load_module("contact_sheet_lib", HERE / "contact_sheet_lib.py")
exr_io = load_module("exr_io", HERE / "blender" / "exr_io.py")

REFS = REPO / "crates" / "io" / "tests" / "gltf_refs"
LABEL_WIDTH = 200
SCALE = 1


def find_glint(explicit):
    if explicit:
        return explicit
    for candidate in (
        shutil.which("glint"),
        os.path.join(os.environ.get("CARGO_TARGET_DIR", ""), "release", "glint"),
        str(REPO / "target" / "release" / "glint"),
    ):
        if candidate and os.path.isfile(candidate):
            return candidate
    raise SystemExit(
        "no glint binary: build it (cargo build --release -p glint-cli) or --glint"
    )


def rgb(data):
    return np.stack([data["R"], data["G"], data["B"]], -1)


def render_glint(glint, model, entry, spp, scratch):
    out = scratch / f"{entry['model']}.exr"
    integrator = "volpath" if uses_volume(model) else "path"
    command = [glint, "render", str(model), "-o", str(out), "-w", str(entry["width"])]
    command += ["-h", str(entry["height"]), "-r", str(spp), "--integrator", integrator]
    result = subprocess.run(
        command, check=False, capture_output=True, text=True, timeout=600
    )
    if result.returncode != 0:
        return None, (result.stderr.strip().splitlines() or ["failed"])[-1]
    return rgb(exr_io.read_exr(str(out))), None


def uses_volume(path):
    data = Path(path).read_bytes()
    return b"KHR_materials_volume" in data


def tile_with_text(width, height, text):
    tile = np.full((height, width, 3), 60, np.uint8)
    words, line, y = text.split(), "", 4
    for word in words:
        if sheet.text_width(line + " " + word) > width - 8 and line:
            sheet.draw_text(tile, line, 4, y)
            line, y = word, y + 10
        else:
            line = (line + " " + word).strip()
        if y > height - 12:
            break
    sheet.draw_text(tile, line, 4, y)
    return tile


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--glint")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--out", default=str(REPO / "docs" / "gltf-contact-sheet.png"))
    args = parser.parse_args()
    glint = find_glint(args.glint)
    manifest = json.loads((REFS / "manifest.json").read_text())
    rows = []
    entries = manifest["models"]
    width, height = entries[0]["width"], entries[0]["height"]
    header = np.zeros((20, LABEL_WIDTH + 2 * width + 8, 3), np.uint8)
    sheet.draw_text(header, "MODEL", 4, 6)
    sheet.draw_text(header, f"GLINT {args.spp} SPP", LABEL_WIDTH, 6)
    spp_ref = entries[0]["beauty_spp"]
    sheet.draw_text(header, f"CYCLES {spp_ref} SPP", LABEL_WIDTH + width + 8, 6)
    rows.append(header)
    with tempfile.TemporaryDirectory() as tmp:
        for entry in entries:
            model = (REPO / entry["path"]).resolve()
            reference = rgb(exr_io.read_exr(str(REFS / entry["reference"])))
            image, error = render_glint(glint, model, entry, args.spp, Path(tmp))
            glint_tile = (
                sheet.srgb(image)
                if image is not None
                else tile_with_text(width, height, "GLINT: " + error)
            )
            row = np.zeros((height + 4, LABEL_WIDTH + 2 * width + 8, 3), np.uint8)
            sheet.draw_text(row, entry["model"][:32], 4, 6)
            sheet.draw_text(row, f"camera: {entry['camera']['kind']}", 4, 20)
            sheet.draw_text(row, f"beauty: {entry['beauty']}", 4, 32)
            row[2 : 2 + height, LABEL_WIDTH : LABEL_WIDTH + width] = glint_tile
            x = LABEL_WIDTH + width + 8
            row[2 : 2 + height, x : x + width] = sheet.srgb(reference)
            rows.append(row)
            status = "ok" if image is not None else f"failed: {error}"
            print(f"{entry['model']}: {status}")
    sheet.write_png(args.out, np.concatenate(rows, 0))
    print(f"wrote {args.out} ({os.path.getsize(args.out)} bytes)")


if __name__ == "__main__":
    main()
