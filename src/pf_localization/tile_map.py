"""pf_tile_map: a large map made by repeating a map_server map (its PGM and YAML).

    pf_tile_map maps/warehouse.yaml OUT_DIR [--across 5] [--up 2.5]

writes OUT_DIR/<name>_tiled.pgm and .yaml: the map's image repeated `across`
times along x and `up` times along y (fractions cut the last copy), from the
same origin and resolution. maps/warehouse.yaml tiled 5 x 2.5 is a 200 x 600 m
floor of 12 000 x 4 000 cells, the size a distribution centre has: what the
big-building measurements in docs/performance.md load. The output is large
(48 MB) and is not committed.
"""
import argparse
import os
import sys


def read_pgm(path):
    """Width, height, maximum and the pixel bytes (top row first) of a binary (P5) PGM."""
    with open(path, 'rb') as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b'#':
            pos = data.index(b'\n', pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b'P5':
        raise ValueError('%s: not a binary PGM (P5), starts with %r' % (path, fields[0]))
    width, height, maximum = (int(v) for v in fields[1:])
    if maximum > 255:
        raise ValueError('%s: 16-bit PGM not supported' % path)
    pixels = data[pos + 1:pos + 1 + width * height]
    if len(pixels) != width * height:
        raise ValueError('%s: %d pixel bytes for %d x %d' % (path, len(pixels), width, height))
    return width, height, maximum, pixels


def tile(width, height, pixels, across, up):
    """The image repeated across x up times, anchored at its lower-left corner (the map's origin)."""
    out_w, out_h = round(width * across), round(height * up)
    rows = [pixels[r * width:(r + 1) * width] for r in range(height)]
    wide = [(row * (out_w // width + 1))[:out_w] for row in rows]
    # Bottom-up: output row k from the bottom is input row k % height from the bottom.
    out = [wide[height - 1 - (k % height)] for k in range(out_h)]
    out.reverse()
    return out_w, out_h, b''.join(out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('map', help='map_server YAML of the map to repeat')
    parser.add_argument('out_dir')
    parser.add_argument('--across', type=float, default=5.0, help='copies along x (default 5)')
    parser.add_argument('--up', type=float, default=2.5, help='copies along y (default 2.5)')
    args = parser.parse_args(argv)
    if not (args.across >= 1.0 and args.up >= 1.0):
        parser.error('--across and --up must be at least 1')
    with open(args.map) as f:
        lines = f.read().splitlines()
    image = next((ln.split(':', 1)[1].strip() for ln in lines if ln.startswith('image:')), None)
    if image is None:
        parser.error('%s has no image: line' % args.map)
    image_path = os.path.join(os.path.dirname(os.path.abspath(args.map)), image)
    try:
        width, height, maximum, pixels = read_pgm(image_path)
    except (OSError, ValueError) as e:
        print('pf_tile_map: %s' % e, file=sys.stderr)
        return 2
    out_w, out_h, out = tile(width, height, pixels, args.across, args.up)
    os.makedirs(args.out_dir, exist_ok=True)
    name = os.path.splitext(os.path.basename(args.map))[0] + '_tiled'
    with open(os.path.join(args.out_dir, name + '.pgm'), 'wb') as f:
        f.write(b'P5\n%d %d\n%d\n' % (out_w, out_h, maximum))
        f.write(out)
    with open(os.path.join(args.out_dir, name + '.yaml'), 'w') as f:
        for ln in lines:
            f.write(('image: %s.pgm' % name if ln.startswith('image:') else ln) + '\n')
    print('pf_tile_map: %s: %d x %d cells' % (os.path.join(args.out_dir, name + '.yaml'), out_w, out_h))
    return 0


if __name__ == '__main__':
    sys.exit(main())
