#!/usr/bin/env python3
"""Make docs/images/class-report.png, the guide's picture of a class report, from a report page.

    python tools/make_class_report_image.py COURSE/reports/ASSIGNMENT/class-report.html

The page is the one ``geomlib-course report`` writes; the guide's picture is of the simulated
class of ``tests/course_class.py`` (22 students handing in notebook 01), whose report the test
``tests/test_course.py::test_the_html_report_shows_the_counts_a_picture_and_the_flags`` writes
under pytest's ``--basetemp``. Headless Chromium (as the browser tests use) draws the whole
page; the PNG is saved as a 256-colour palette image, which keeps the picture near 110 KB and
every colour of the plots' legend apart (64 colours merge the catch-all into the named mistakes).
"""

import argparse
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "images" / "class-report.png"
WIDTH = 1000  # pixels: the report's tables are read at this width without wrapping the ids
COLOURS = 256


def shoot(page, out, browser="/usr/bin/chromium"):
    """Draw ``page`` (an HTML file) whole into the palette PNG ``out``."""
    import io

    from PIL import Image
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=browser)
        tab = chromium.new_page(viewport={"width": WIDTH, "height": 800})
        tab.goto(Path(page).resolve().as_uri())
        png = tab.screenshot(full_page=True)
        chromium.close()
    Image.open(io.BytesIO(png)).convert("RGB").quantize(COLOURS).save(out, optimize=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page", help="a class-report.html written by geomlib-course report")
    parser.add_argument("--out", default=str(OUT), help="the PNG to write (default: the guide's picture)")
    args = parser.parse_args()
    shoot(args.page, args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
