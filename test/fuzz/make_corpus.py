#!/usr/bin/env python3
"""Writes the fuzzers' seed corpus: a handful of small, valid inputs.

    python3 test/fuzz/make_corpus.py        # rewrites test/fuzz/corpus/*/seed_*

The byte format is the one test/fuzz/fuzz_input.h reads: u8, little-endian
u16, and num(lo, hi) = a selector byte (>= 10 for an ordinary value) then a
u16 scaled onto [lo, hi] (selector 8: a raw double; 0..7 special values). The
order of the fields is documented at the top of fuzz_core.cc and
fuzz_map_loader.cc. Deterministic: the same script writes the same bytes.
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

NAN, INF, NINF, ZERO, MINUS_ONE, HUGE, NHUGE, DENORM = range(8)


def u8(v):
    return bytes([v & 0xFF])


def num(v, lo, hi):
    """An ordinary value, quantised onto [lo, hi]; v must lie inside."""
    q = round((v - lo) / (hi - lo) * 65535)
    return bytes([0x10]) + struct.pack("<H", max(0, min(65535, q)))


def special(kind):
    return bytes([kind])


def raw(v):
    return bytes([8]) + struct.pack("<d", v)


def pose(x, y, yaw, xy, a):
    return num(x, -xy, xy) + num(y, -xy, xy) + num(yaw, -a, a)


def params(flags=0, min_p=50, max_p=150, max_beams=32, recovery=None, omni=False,
           sigma_hit=0.2, z_rand=0.05, kld_bin_xy=None, cluster_xy=None, ess=0.5, refine=False):
    b = u8(flags | (1 if omni else 0) | (16 if recovery else 0) | (32 if refine else 0))
    b += u8(min_p - 1)                      # min_particles = raw % 100 + 1
    b += u8(max_p - min_p)                  # max_particles = min + raw % 101
    b += num(0.05, 0.001, 0.5)              # kld_err
    b += num(0.99, 0.0, 1.0)                # kld_confidence
    b += kld_bin_xy or num(0.5, 0.01, 2.0)  # kld_bin_xy
    b += num(0.17, 0.01, 1.0)               # kld_bin_yaw
    b += num(0.1, 0.0, 0.5)                 # update_min_d
    b += num(0.3, 0.0, 1.0)                 # update_min_a
    b += num(ess, 0.0, 1.0)                 # resample_ess_fraction
    b += u8(7)                              # seed
    for _ in range(5):
        b += num(0.1, 0.0, 0.5)             # alpha1..5
    b += num(0.95, 0.0, 1.0)                # z_hit
    b += num(z_rand, 0.0, 1.0)              # z_rand
    b += num(sigma_hit, 0.01, 1.0)          # sigma_hit
    b += num(2.0, 0.05, 3.0)                # max_distance
    b += u8(max_beams + 2)                  # max_beams
    b += cluster_xy or num(0.5, 0.05, 2.0)  # cluster_xy
    b += num(0.5, 0.05, 1.5)                # cluster_yaw
    if recovery:
        b += num(recovery[0], 0.0, 0.1) + num(recovery[1], 0.0, 1.0)
    return b


ROOM_W, ROOM_H, RES = 30, 20, 0.1  # a 3 m x 2 m walled room


def room_map(style=1):
    mflags = 3 | (style << 3)               # no size fault
    return (u8(mflags) + u8(ROOM_W - 1) + u8(ROOM_H - 1) + num(RES, 0.01, 0.5)
            + num(0.0, -20, 20) + num(0.0, -20, 20) + num(0.0, -4, 4))


def ray_ranges(x, y, yaw, n, sensor_x=0.1):
    """Ranges to the room's inner walls (a cell thick) from a laser at the pose."""
    sx, sy = x + sensor_x * math.cos(yaw), y + sensor_x * math.sin(yaw)
    lo_x, hi_x, lo_y, hi_y = RES, (ROOM_W - 1) * RES, RES, (ROOM_H - 1) * RES
    out = []
    for i in range(n):
        a = yaw - math.pi + i * 2 * math.pi / n
        c, s = math.cos(a), math.sin(a)
        ts = []
        if c > 1e-9: ts.append((hi_x - sx) / c)
        if c < -1e-9: ts.append((lo_x - sx) / c)
        if s > 1e-9: ts.append((hi_y - sy) / s)
        if s < -1e-9: ts.append((lo_y - sy) / s)
        out.append(min(ts))
    return out


def scan(ranges, bad=()):
    n = len(ranges)
    b = u8(n) + num(-math.pi, -4, 4) + num(2 * math.pi / n, -0.2, 0.2)
    b += num(0.05, 0.0, 1.0) + num(8.0, 0.0, 30.0) + pose(0.1, 0.0, 0.0, 0.5, 4.0)
    for i, r in enumerate(ranges):
        b += special(NAN) if i in bad else num(min(r, 12.0), 0.0, 12.0)
    return b


def cov(vx=0.05, vy=0.05, va=0.05):
    return (num(vx, 0, 0.5) + num(vy, 0, 0.5) + num(va, 0, 0.5)
            + num(0, -0.05, 0.05) * 3)


def core_seeds():
    seeds = {}
    # 1. Tracking in a walled room: Gaussian start, moves, a new scan, a no-motion update;
    #    once as it is, once with the estimate refined against the map.
    for name, refine in (("tracking", False), ("tracking_refined", True)):
        b = params(refine=refine) + room_map(1)
        b += u8(0) + pose(1.5, 1.0, 0.0, 25.0, 4.0) + cov()
        b += pose(0.0, 0.0, 0.0, 5.0, 4.0)                     # odometry
        b += scan(ray_ranges(1.5, 1.0, 0.0, 72), bad={3, 40})
        b += u8(7)                                              # 8 steps
        b += u8(0) + pose(0.2, 0.0, 0.05, 0.5, 0.7)
        b += u8(0) + pose(0.2, 0.0, 0.05, 0.5, 0.7)
        b += u8(4) + scan(ray_ranges(1.9, 1.0, 0.1, 72))
        b += u8(6)
        b += u8(1) + pose(-0.3, 0.05, -0.4, 0.5, 0.7)
        b += u8(5) + num(0.0, -1, 1) + u8(1)                   # angle_increment 0
        b += u8(2) + pose(0.1, 0.0, 0.6, 0.5, 0.7)
        b += u8(9) + pose(0.01, 0.0, 0.0, 0.05, 0.1)
        seeds[name] = b
    # 2. Global localization, omni drive, recovery on.
    b = params(omni=True, recovery=(0.001, 0.1), min_p=20, max_p=200) + room_map(1)
    b += u8(1) + pose(0.0, 0.0, 0.0, 5.0, 4.0)
    b += scan(ray_ranges(1.0, 0.6, 1.0, 90))
    b += u8(5)
    for _ in range(3):
        b += u8(0) + pose(0.3, 0.1, 0.2, 0.5, 0.7)
    b += u8(8) + u8(6)
    seeds["global"] = b
    # 3. A map from bytes, Gaussian near a free cell, NaN odometry then good again.
    b = params(max_beams=10, sigma_hit=0.1, z_rand=0.0) + room_map(0)
    b += bytes((i * 37) % 256 for i in range(ROOM_W * ROOM_H))
    b += u8(2) + pose(0, 0, 0, 25.0, 4.0) + u8(17) + cov(0.1, 0.1, 0.3)
    b += pose(1.0, 1.0, 0.0, 5.0, 4.0)
    b += scan([0.5 + 0.05 * i for i in range(40)])
    b += u8(4)
    b += u8(3) + special(NAN) + num(0.0, -1e3, 1e3) + num(0.0, -10, 10)
    b += u8(3) + num(1.0, -1e3, 1e3) + num(1.0, -1e3, 1e3) + num(0.0, -10, 10)
    b += u8(0) + pose(0.3, 0.0, 0.0, 0.5, 0.7)
    b += u8(7) + u8(0) + pose(0.3, 0.0, 0.0, 0.5, 0.7)
    seeds["bytes_map_nan_odom"] = b
    # 4. Invalid parameters: min_particles = -1.
    seeds["bad_params"] = u8(0) + u8(1) + u8(10)
    # 5. A map with a size fault (width 0) and one with no free cell.
    seeds["bad_map"] = params() + u8(0) + u8(5) + u8(5) + u8(0) + num(0.05, 0.01, 0.5)
    b = params() + u8(3 | (3 << 3)) + u8(3) + u8(3) + num(0.05, 0.01, 0.5)
    b += num(0, -20, 20) * 3 + bytes([100] * 16) + u8(1)
    seeds["no_free_cell"] = b
    # 6. A 1 x 1 free map, scans with special ranges.
    b = params(min_p=5, max_p=20) + u8(3 | (2 << 3)) + u8(0) + u8(0) + num(0.05, 0.01, 0.5)
    b += num(0, -20, 20) * 3
    b += u8(0) + pose(0.0, 0.0, 0.0, 25.0, 4.0) + cov()
    b += pose(0.0, 0.0, 0.0, 5.0, 4.0)
    b += (u8(8) + num(0.0, -4, 4) + num(0.1, -0.2, 0.2) + num(0.05, 0, 1) + num(8, 0, 30)
          + pose(0, 0, 0, 0.5, 4.0) + special(NAN) + special(INF) + special(ZERO)
          + special(MINUS_ONE) + special(HUGE) + raw(1e39) + num(1.0, 0, 12) + num(2.0, 0, 12))
    b += u8(3) + u8(6) + u8(0) + pose(0.5, 0, 0, 0.5, 0.7)
    seeds["tiny_map_special_ranges"] = b
    return seeds


P5_3x2 = b"P5\n3 2\n255\n" + bytes([0, 254, 205, 254, 0, 128])


def map_seeds():
    seeds = {}
    seeds["p5_trinary"] = u8(0) + u8(0) + P5_3x2
    seeds["p2_scale_comment"] = (u8(0) + u8(1) + b"P2\n# CREATOR: GIMP\n4 2\n15\n"
                                 b"0 3 7 15\n15 12 8 0\n")
    seeds["p6_raw_negate"] = u8(0) + u8(2 | 4) + b"P6 2 2 255\n" + bytes(range(0, 240, 20))
    seeds["p5_16bit"] = u8(0) + u8(0) + b"P5 2 2 65535\n" + bytes([0, 0, 255, 255, 128, 0, 1, 2])
    seeds["p3_thresholds"] = (u8(0) + u8(8 | 1) + u8(40) + u8(130)
                              + b"P3\n2 1\n255\n10 20 30 200 210 220\n")
    seeds["yaml_basic"] = u8(1) + (b"image: map.pgm\nresolution: 0.05\n"
                                   b"origin: [-10.0, -5.0, 0.0]\nnegate: 0\n"
                                   b"occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    seeds["yaml_scale"] = u8(1) + (b"image: ./map.pgm\nresolution: 0.1\norigin: [1, 2, 3.5]\n"
                                   b"negate: true\nmode: scale\noccupied_thresh: 0.9\n"
                                   b"free_thresh: 0.1\n")
    seeds["yaml_flow_raw"] = u8(1) + (b"{image: map.pgm, resolution: 2.5e-2, "
                                      b"origin: [0, 0, 0], mode: raw}\n")
    return seeds


def tracking_start(prm):
    """params + the walled room + a Gaussian start at (1.5, 1.0, 0) + a good scan."""
    b = prm + room_map(1)
    b += u8(0) + pose(1.5, 1.0, 0.0, 25.0, 4.0) + cov()
    b += pose(0.0, 0.0, 0.0, 5.0, 4.0)
    b += scan(ray_ranges(1.5, 1.0, 0.0, 72))
    return b


def crash_inputs():
    """Hand-made reproducers of the bugs the fuzzer found (test/fuzz/crashes/README.md)."""
    seeds = {}
    # A tiny cluster bin (1e-300 m passes validate()): floor(x / 1e-300) does not fit int64.
    seeds["fuzz_core-cluster_bin_overflow"] = tracking_start(params(cluster_xy=raw(1e-300)))
    # The same in KLD-sampling's histogram, on the first resample (ess fraction 1).
    seeds["fuzz_core-kld_bin_overflow"] = (tracking_start(params(kld_bin_xy=raw(1e-300), ess=1.0))
                                           + u8(1) + u8(9) + pose(0, 0, 0, 0.05, 0.1))
    # A finite but absurd odometry jump (1e300 m): the motion noise overflows to inf,
    # particles become inf/NaN, and the likelihood table is indexed with (int)NaN.
    seeds["fuzz_core-odometry_jump"] = (tracking_start(params())
                                        + u8(2) + u8(9) + pose(0, 0, 0, 0.05, 0.1)
                                        + u8(3) + special(HUGE) + special(HUGE)
                                        + num(0.0, -10, 10))
    # A valid scan whose range_max (1e39) and one range (3e38 m) are finite but so
    # large that the end point in cells overflows float: inf - inf = NaN -> (int)NaN.
    b = tracking_start(params()) + u8(1) + u8(4)
    b += (u8(2) + num(0.7, -4, 4) + num(0.1, -0.2, 0.2) + num(0.05, 0, 1) + raw(1e39)
          + pose(0, 0, 0, 0.5, 4.0) + raw(3e38) + num(1.0, 0, 12))
    seeds["fuzz_core-scan_endpoint_overflow"] = b
    # A 3 x 1 map with no free cell, a Gaussian start on it, then scans that stop
    # fitting: recovery drew random particles from the empty free-cell list.
    # Found by the 10-minute run of 2026-11-30 and minimised by libFuzzer
    # (-minimize_crash=1), so kept as its bytes.
    seeds["fuzz_core-injection_without_free_cells"] = bytes.fromhex(
        "0031641023191070fd10093f10602910333310cc4c100033073310331080334f"
        "63637570616e637947726964cd0c0b21003238422210133b10724f0b02001005"
        "2f1000801000801000800010ae87101e85100080109a1910fffffffeffffffff"
        "d5d5d5d5d5d5d5ffffffffffffff00101910271b10df1d10792a101212121212"
        "121212f0696effff070000000000e5e59a19109a1910e5e5e5e5e5e510000100"
        "0041100010008010999910000010")
    return seeds


def write_crashes():
    folder = os.path.join(HERE, "crashes")
    os.makedirs(folder, exist_ok=True)
    for name, data in crash_inputs().items():
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
    print(f"{folder}: {len(crash_inputs())} reproducers")


def write(target, seeds):
    folder = os.path.join(HERE, "corpus", target)
    os.makedirs(folder, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(folder, "seed_" + name), "wb") as f:
            f.write(data)
    print(f"{folder}: {len(seeds)} seeds")


if __name__ == "__main__":
    write("fuzz_core", core_seeds())
    write("fuzz_map_loader", map_seeds())
    write_crashes()
