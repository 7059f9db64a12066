#!/usr/bin/python3
"""rostest checker: pf_node's layer of where the world no longer matches its map.

Subscribes to pf_map_changes (nav_msgs/OccupancyGrid, latched: -1 unseen, 0 seen as mapped, 100
added, 50 removed) and, once the bag's /clock has stopped for `idle_timeout` s of wall time (or
after `wall_timeout`), scores the latest layer with pf_evaluate's change_metrics: against the true
change mask when `mask` names one (pf_simulator --change-mask), else only the share of the cells
seen that it marks.

Private params:
    mask                  the true change mask's YAML (optional)
    min_precision         with a mask: at least this precision (a marked cell within one cell of a
                          true change of its kind)
    min_recall            with a mask: at least this recall of the true changes the lidar saw
    max_changed_share     at most this share of the cells seen marked changed (default 1)
    min_cells_seen        the layer must have seen at least this many cells (default 1000)
    idle_timeout  [s]     wall time without /clock that ends the watch (default 5)
    wall_timeout  [s]     wall time after which it scores what it has (default 150)
"""
import sys
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from nav_msgs.msg import OccupancyGrid
from rosgraph_msgs.msg import Clock

from pf_localization import evaluate

PKG = 'pf_localization'
# OccupancyGrid values -> the image's pixels (evaluate.CHANGE_*).
PIXELS = {-1: evaluate.CHANGE_UNSEEN, 0: evaluate.CHANGE_AS_MAPPED, 100: evaluate.CHANGE_ADDED,
          50: evaluate.CHANGE_REMOVED}


def to_pixels(msg):
    """The layer's cells as the image pf_bag_runner --changes writes: row 0 the map's top row."""
    values = np.array(msg.data, dtype=np.int8).reshape(msg.info.height, msg.info.width)
    pixels = np.full(values.shape, evaluate.CHANGE_UNSEEN, dtype=np.uint8)
    for value, pixel in PIXELS.items():
        pixels[values == value] = pixel
    return pixels[::-1]


class MapChangesChecker(unittest.TestCase):
    def test_map_changes(self):
        rospy.init_node('map_changes_checker')
        lock = threading.Lock()
        latest, last_clock = [None], [None]

        def on_layer(msg):
            with lock:
                latest[0] = msg

        def on_clock(_):
            with lock:
                last_clock[0] = time.monotonic()

        rospy.Subscriber('pf_map_changes', OccupancyGrid, on_layer, queue_size=1)
        rospy.Subscriber('/clock', Clock, on_clock, queue_size=1)
        idle = rospy.get_param('~idle_timeout', 5.0)
        start = time.monotonic()
        deadline = start + rospy.get_param('~wall_timeout', 150.0)
        while time.monotonic() < deadline and not rospy.is_shutdown():
            with lock:
                clock = last_clock[0] if last_clock[0] is not None else start
                done = latest[0] is not None and time.monotonic() - clock > idle
            if done:
                break
            time.sleep(0.2)
        with lock:
            msg = latest[0]
        self.assertIsNotNone(msg, 'no pf_map_changes received')
        mask_path = rospy.get_param('~mask', '')
        mask = evaluate.read_change_image(mask_path) if mask_path else None
        m = evaluate.change_metrics(to_pixels(msg), mask)
        text = 'map_changes_checker:' + evaluate.describe_changes(m)[len('  map changes:'):]
        print(text, flush=True)
        self.assertGreaterEqual(m['cells_seen'], rospy.get_param('~min_cells_seen', 1000), text)
        self.assertLessEqual(m['changed_share_of_seen'], rospy.get_param('~max_changed_share', 1.0),
                             text)
        if mask is not None:
            self.assertIsNotNone(m['precision'], 'nothing marked: ' + text)
            self.assertGreaterEqual(m['precision'], rospy.get_param('~min_precision', 0.0), text)
            self.assertGreaterEqual(m['recall'], rospy.get_param('~min_recall', 0.0), text)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'map_changes_checker', MapChangesChecker, sys.argv)
