#!/usr/bin/python3
"""Tiles PNG pictures made by cdem-strain into one figure for a README.

usage: montage.py OUT.png COLUMNS [--width PX] [--title T1] IN1.png [--title T2] IN2.png ...

COLUMNS is the number of pictures per row, or a comma list per row ("1,2": one picture in
the first row, two in the next and every later row). Each input is scaled to its column
width (total width PX, default 1000) and may carry a title line above it. The result is saved as a palette PNG (256 colours) so that it stays
small (a few hundred KB at 1000 px). Needs Pillow (python3-pil)."""
import sys
from PIL import Image, ImageDraw, ImageFont

def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__)
    out, cols = argv[1], [int(c) for c in argv[2].split(",")]
    width, title, items = 1000, None, []
    args = argv[3:]
    i = 0
    while i < len(args):
        if args[i] == "--width":
            width = int(args[i + 1]); i += 2; continue
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
    sheet.quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(out, optimize=True)

if __name__ == "__main__":
    main(sys.argv)
