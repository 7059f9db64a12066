"""pf_tile_map: the big-building test map is the small map repeated from its origin."""
import os
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, 'src'))
from pf_localization import tile_map  # noqa: E402


def write_map(folder, width, height, pixels):
    with open(os.path.join(folder, 'm.pgm'), 'wb') as f:
        f.write(b'P5\n# made by a test\n%d %d\n255\n' % (width, height) + bytes(pixels))
    with open(os.path.join(folder, 'm.yaml'), 'w') as f:
        f.write('image: m.pgm\nresolution: 0.1\norigin: [-1, -2, 0]\nnegate: 0\n')
    return os.path.join(folder, 'm.yaml')


class TileMapTest(unittest.TestCase):
    def test_copies_are_anchored_at_the_lower_left_corner(self):
        # 3 x 2, top row first: a b c / d e f. 2 x 1.5 copies: 6 x 3, and
        # the half copy is the top half of the image, its bottom row (d e f)
        # repeated above the whole copy.
        with tempfile.TemporaryDirectory() as d:
            yaml = write_map(d, 3, 2, b'abcdef')
            self.assertEqual(0, tile_map.main([yaml, d, '--across', '2', '--up', '1.5']))
            w, h, maximum, pixels = tile_map.read_pgm(os.path.join(d, 'm_tiled.pgm'))
            self.assertEqual((6, 3, 255), (w, h, maximum))
            self.assertEqual(b'defdef' b'abcabc' b'defdef', pixels)
            with open(os.path.join(d, 'm_tiled.yaml')) as f:
                text = f.read()
            self.assertIn('image: m_tiled.pgm\n', text)
            self.assertIn('origin: [-1, -2, 0]\n', text)
            self.assertIn('resolution: 0.1\n', text)

    def test_the_bundled_warehouse_makes_the_200_by_600_m_floor(self):
        with tempfile.TemporaryDirectory() as d:
            out = subprocess.run(['/usr/bin/python3', os.path.join(REPO, 'scripts', 'pf_tile_map'),
                                  os.path.join(REPO, 'maps', 'warehouse.yaml'), d],
                                 capture_output=True, text=True, check=True).stdout
            self.assertIn('12000 x 4000 cells', out)
            w, h, _, pixels = tile_map.read_pgm(os.path.join(d, 'warehouse_tiled.pgm'))
            self.assertEqual((12000, 4000), (w, h))
            sw, sh, _, small = tile_map.read_pgm(os.path.join(REPO, 'maps', 'warehouse.pgm'))
            # The bottom-left copy is the map itself.
            for r in (0, sh // 2, sh - 1):
                self.assertEqual(small[(sh - 1 - r) * sw:(sh - r) * sw],
                                 pixels[(h - 1 - r) * w:(h - 1 - r) * w + sw])

    def test_not_a_binary_pgm_is_refused_with_its_name(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, 'm.pgm'), 'wb') as f:
                f.write(b'P2\n1 1\n255\n0\n')
            with open(os.path.join(d, 'm.yaml'), 'w') as f:
                f.write('image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n')
            proc = subprocess.run(['/usr/bin/python3', os.path.join(REPO, 'scripts', 'pf_tile_map'),
                                   os.path.join(d, 'm.yaml'), d], capture_output=True, text=True)
            self.assertEqual(2, proc.returncode)
            self.assertIn('not a binary PGM', proc.stderr)


if __name__ == '__main__':
    unittest.main()
