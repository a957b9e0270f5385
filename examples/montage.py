#!/usr/bin/python3
"""Tiles PNG pictures made by cdem-strain into one figure for a README.

usage: montage.py OUT.png COLUMNS [--width PX] [--title T1] IN1.png [--title T2] IN2.png ...

Each input is scaled to the column width (total width PX, default 1000) and may carry a
title line above it. The result is saved as a palette PNG (256 colours) so that it stays
small (a few hundred KB at 1000 px). Needs Pillow (python3-pil)."""
import sys
from PIL import Image, ImageDraw, ImageFont

def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__)
    out, cols = argv[1], int(argv[2])
    width, title, items = 1000, None, []
    args = argv[3:]
    i = 0
    while i < len(args):
        if args[i] == "--width":
            width = int(args[i + 1]); i += 2; continue
        if args[i] == "--title":
            title = args[i + 1]; i += 2; continue
        items.append((args[i], title)); title = None; i += 1
    colw = width // cols
    try:
        font = ImageFont.truetype("DejaVuSans.ttf", 16)
    except OSError:
        font = ImageFont.load_default()
    tiles = []
    for path, t in items:
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
    rows = [tiles[k:k + cols] for k in range(0, len(tiles), cols)]
    heights = [max(t.height for t in r) for r in rows]
    sheet = Image.new("RGB", (colw * cols, sum(heights)), "white")
    y = 0
    for r, h in zip(rows, heights):
        for c, t in enumerate(r):
            sheet.paste(t, (c * colw, y))
        y += h
    sheet.quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(out, optimize=True)

if __name__ == "__main__":
    main(sys.argv)
