#!/usr/bin/python3
"""A bounded CPU hog for the rostests: busy loops on ~processes
processes (default: every core) for ~duration seconds of wall time (default
60), started after ~delay s, then it exits. Run as an ordinary <node>: it
takes the CPU from pf_node the way another process on a robot computer
would. Its processes are its children and end with it (SIGTERM)."""

import multiprocessing
import os
import signal
import sys
import time

import rospy


def spin(until):
    x = 0
    while time.time() < until:
        x += 1


def main():
    rospy.init_node('cpu_hog')
    n = int(rospy.get_param('~processes', 0)) or os.cpu_count() or 2
    duration = float(rospy.get_param('~duration', 60.0))
    time.sleep(float(rospy.get_param('~delay', 0.0)))
    until = time.time() + duration
    procs = [multiprocessing.Process(target=spin, args=(until,), daemon=True) for _ in range(n)]
    for p in procs:
        p.start()
    rospy.loginfo('cpu_hog: %d busy processes for %.0f s', n, duration)

    def stop(*_):
        for p in procs:
            p.terminate()
        sys.exit(0)
    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    for p in procs:
        p.join()
    rospy.loginfo('cpu_hog: done')
    while not rospy.is_shutdown():
        time.sleep(0.5)


if __name__ == '__main__':
    main()
