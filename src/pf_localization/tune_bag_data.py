"""What pf_tune's self-supervised score reads, cached per (worker) process: a bag's scans, the
laser's pose on the robot and the odometry at each scan, and a map's distance to the nearest
occupied cell."""
import math
import os
import sys
import types

import numpy as np
import yaml

from pf_localization import evaluate as pfe
from pf_localization.tune_space import TuneError


def _worker_cache():
    """A module that lives as long as the (worker) process: caches of bag data and maps. It hangs
    off sys.modules so that it holds also for a function a Dask client shipped by value."""
    m = sys.modules.get('_pf_tune_cache')
    if m is None:
        m = types.ModuleType('_pf_tune_cache')
        m.bags, m.maps = {}, {}
        sys.modules['_pf_tune_cache'] = m
    return m


def yaw_of(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


# --------------------------------------------------------------------- data read from bags
def bag_has_topic(bag, topic):
    """Whether the bag holds messages on topic; an unreadable bag has none (its runs will fail, be
    reported and scored as failures, and the study goes on)."""
    import rosbag
    try:
        with rosbag.Bag(bag) as b:
            info = b.get_type_and_topic_info().topics
            return topic in info and info[topic].message_count > 0
    except Exception as e:
        print('pf_tune: warning: cannot read %s: %s' % (bag, e), file=sys.stderr)
        return False


def read_bag_data(bag, scan_topic='/scan', odom_topic='/odom', odom_frame='odom', base_frame='base_link'):
    """What the self-supervised score needs from a bag, cached per process: the scans (stamps,
    ranges, beam angles), the laser's pose on the robot and the odometry at each scan."""
    c = _worker_cache()
    key = (os.path.realpath(bag), os.path.getmtime(bag), scan_topic, odom_topic)
    if key in c.bags:
        return c.bags[key]
    import rosbag
    stamps, ranges, angles, limits = [], [], None, None
    laser_frame, laser = None, None
    odom_t, odom_p, tf_t, tf_p = [], [], [], []
    static = {}
    with rosbag.Bag(bag) as b:
        for topic, m, _ in b.read_messages(topics=[scan_topic, odom_topic, '/tf', '/tf_static']):
            if topic == scan_topic:
                r = np.asarray(m.ranges, dtype=np.float32)
                if angles is None or len(angles) != len(r):
                    angles = m.angle_min + m.angle_increment * np.arange(len(r))
                    limits = (m.range_min, m.range_max)
                    laser_frame = m.header.frame_id.lstrip('/')
                if len(r) != len(angles):
                    continue
                stamps.append(m.header.stamp.to_sec())
                ranges.append(r)
            elif topic == odom_topic:
                p = m.pose.pose
                odom_t.append(m.header.stamp.to_sec())
                odom_p.append((p.position.x, p.position.y, yaw_of(p.orientation)))
            else:
                for t in m.transforms:
                    parent, child = t.header.frame_id.lstrip('/'), t.child_frame_id.lstrip('/')
                    tr, q = t.transform.translation, t.transform.rotation
                    if parent == odom_frame and child == base_frame:
                        tf_t.append(t.header.stamp.to_sec())
                        tf_p.append((tr.x, tr.y, yaw_of(q)))
                    elif (parent, child) not in static:
                        static[(parent, child)] = (tr.x, tr.y, yaw_of(q))
    if not stamps:
        raise TuneError('bag %s has no %s scans' % (bag, scan_topic))
    if (base_frame, laser_frame) in static:
        laser = static[(base_frame, laser_frame)]
    elif laser_frame == base_frame:
        laser = (0.0, 0.0, 0.0)
    else:
        laser = (0.0, 0.0, 0.0)
        print('pf_tune: warning: no %s -> %s transform in %s: laser assumed at the robot\'s origin'
              % (base_frame, laser_frame, bag), file=sys.stderr)
    ot, op = (odom_t, odom_p) if odom_t else (tf_t, tf_p)
    order = np.argsort(ot) if ot else []
    ot = np.asarray(ot, dtype=float)[order] if len(ot) else np.zeros(0)
    op = np.asarray(op, dtype=float)[order] if len(op) else np.zeros((0, 3))
    data = {'t': np.asarray(stamps), 'ranges': np.vstack(ranges), 'angles': np.asarray(angles, dtype=float),
            'range_min': float(limits[0]), 'range_max': float(limits[1]), 'laser': laser,
            'odom_t': ot, 'odom': op}
    c.bags[key] = data
    return data


def load_distance_map(yaml_path):
    """map_server YAML -> (distance to the nearest occupied cell [m] per cell, resolution, origin x, y)."""
    c = _worker_cache()
    key = (os.path.realpath(yaml_path), os.path.getmtime(yaml_path))
    if key in c.maps:
        return c.maps[key]
    from scipy import ndimage
    with open(yaml_path) as f:
        info = yaml.safe_load(f)
    image = os.path.join(os.path.dirname(os.path.abspath(yaml_path)), info['image'])
    if image.lower().endswith(('.pgm', '.ppm', '.pnm')):
        v = pfe.read_pnm(image)
    else:
        from PIL import Image
        v = np.asarray(Image.open(image).convert('L'), dtype=float) / 255.0
    occ = v if int(info.get('negate', 0)) else 1.0 - v
    occupied = occ > float(info.get('occupied_thresh', 0.65))
    res = float(info['resolution'])
    dist = ndimage.distance_transform_edt(~occupied) * res
    dist = dist[::-1]  # row 0 at the origin's y, as the map frame
    origin = [float(x) for x in info['origin']]
    c.maps[key] = (dist, res, origin[0], origin[1])
    return c.maps[key]
