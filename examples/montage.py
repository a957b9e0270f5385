#!/usr/bin/python3
"""Tiles PNG pictures made by cdem-strain into one figure for a README.

usage: montage.py OUT.png COLUMNS [--width PX] [--max-kb KB] [--title T1] IN1.png [--title T2] IN2.png ...

COLUMNS is the number of pictures per row, or a comma list per row ("1,2": one picture in
the first row, two in the next and every later row). Each input is scaled to its column
width (total width PX, default 1000) and may carry a title line above it. The result is
saved as an RGB PNG of at most --max-kb KB (default 600), scaled down when larger. (It was
a palette PNG of 256 to 32 colours, which posterised the colour bars and the strain
fields' gradients: calibration.png, fig14.png, fig7.png; issue 35.) Needs Pillow
(python3-pil)."""
import os
import sys
from PIL import Image, ImageDraw, ImageFont

def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__)
    out, cols = argv[1], [int(c) for c in argv[2].split(",")]
    width, title, items, max_kb = 1000, None, [], 600
    args = argv[3:]
    i = 0
    while i < len(args):
        if args[i] == "--width":
            width = int(args[i + 1]); i += 2; continue
        if args[i] == "--max-kb":
            max_kb = int(args[i + 1]); i += 2; continue
        if args[i] == "--title":
            title = args[i + 1]; i += 2; continue
        items.append((args[i], title)); title = None; i += 1
    try:
        font = ImageFont.truetype("DejaVuSans.ttf", 16)
    except OSError:
        font = ImageFont.load_default()
    rows, k = [], 0
    while k < len(items):
        n = cols[min(len(rows), len(cols) - 1)]
        rows.append(items[k:k + n]); k += n
    tiled = []
    for r, row in enumerate(rows):
        n = cols[min(r, len(cols) - 1)]
        colw = width // n
        tiles = []
        for path, t in row:
            im = Image.open(path).convert("RGB")
            h = round(im.height * colw / im.width)
            im = im.resize((colw, h), Image.LANCZOS)
            if t:
                th = 24
                tile = Image.new("RGB", (colw, h + th), "white")
                ImageDraw.Draw(tile).text((6, 3), t, fill="black", font=font)
                tile.paste(im, (0, th))
                im = tile
            tiles.append(im)
        tiled.append((colw, tiles))
    sheet = Image.new("RGB", (width, sum(max(t.height for t in ts) for _, ts in tiled)), "white")
    y = 0
    for colw, ts in tiled:
        for c, t in enumerate(ts):
            sheet.paste(t, (c * colw, y))
        y += max(t.height for t in ts)
    # Keep README pictures small (<= max_kb) by a smaller size only: every colour stays.
    for scale in (1.0, 0.85, 0.7, 0.6):
        im = sheet if scale == 1.0 else sheet.resize(
            (round(sheet.width * scale), round(sheet.height * scale)), Image.LANCZOS)
        im.save(out, optimize=True)
        if os.path.getsize(out) <= max_kb * 1024:
            break

if __name__ == "__main__":
    main(sys.argv)
