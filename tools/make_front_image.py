#!/usr/bin/env python3
"""Make the README's picture, docs/images/front.png, from geomlib's own still pictures.

    python tools/make_front_image.py              # writes docs/images/front.png
    python tools/make_front_image.py --out x.png  # somewhere else (the tests do this)

Three views in a row, each ``MeshView(...).still()``, the picture a 3D view of the
workbook shows where no browser draws it: the shipped torus coloured by its Gaussian
curvature from angle deficits (notebook 01), the noisy CAD part (07) and
the same part after implicit smoothing (06). The stills are drawn by geomlib's numpy
rasteriser, so the file is the same on every run (tests/test_docs.py compares it).
The PNG is saved as a 256-colour palette image: the README's picture stays small
(under 150 KB) and the shading keeps enough steps to read.
"""

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "images" / "front.png"
COLOURS = 256
SIZE = (300, 250)  # width and height of each view, pixels


def front_image():
    """(h, w, 3) uint8: the three stills side by side."""
    import geomlib
    from geomlib.teaching.display.stills import in_a_row
    from geomlib.teaching.display.viewer import MeshView

    w, h = SIZE
    V, F = geomlib.load_mesh(geomlib.data_path("torus.obj"))
    K = geomlib.gaussian_curvature(V, F)
    torus = MeshView(
        V, F, K, symmetric=True, width=w, height=h, title="torus: Gaussian curvature", label="K (1/length^2)"
    )
    V, F = geomlib.load_mesh(geomlib.data_path("cad_part_noisy.obj"))
    noisy = MeshView(V, F, width=w, height=h, title="a noisy part")
    P = geomlib.implicit_smoothing(V, F, step=1e-3, iterations=2)
    smooth = MeshView(P, F, frame=V, width=w, height=h, title="after implicit smoothing")
    return in_a_row([view.still() for view in (torus, noisy, smooth)])


def save(image, path):
    from PIL import Image

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    picture = Image.fromarray(image).quantize(COLOURS, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    picture.save(path, format="PNG", optimize=True)
    return path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(OUT), help="the PNG to write (default: docs/images/front.png)")
    args = parser.parse_args(argv)
    path = save(front_image(), args.out)
    print(f"wrote {path} ({path.stat().st_size / 1e3:.0f} KB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
