#!/usr/bin/python3
"""rosbag play, started once a latched topic has a message: for a rostest
whose bag needs something another node of the launch publishes first:
pf_node's first pf_pose (sent once its map is set up and its cloud spread,
before any scan), or a laser's mounting on /tf_static. A fixed delay (play
-d) is not enough on a loaded machine, where starting the launch's nodes and
building the map's fields can take longer than the bag needs to move the
robot away from its initial pose, or into the checker's window.

    <node pkg="pf_localization" type="play_after.py" name="player"
          args="TOPIC [--stall STOP_S EVERY_S] -- PLAY_ARGUMENTS"/>

Waits for TOPIC (any type) up to 60 s of wall time, then becomes rosbag play
with PLAY_ARGUMENTS (and roslaunch's remappings); exits 1 if nothing came.
With --stall, the player is stopped (SIGSTOP) for STOP_S every EVERY_S
seconds of wall time instead, as a slow disk or a loaded machine stops it:
catching up, it sends what it is late with before its next /clock."""

import os
import signal
import subprocess
import sys
import threading
import time

import rospy
from rospy import AnyMsg

WAIT_S = 60.0


def play_stalled(command, stop_s, every_s):
    """Runs `command` in a process group of its own, stopped for stop_s
    every every_s seconds, until it exits; returns its exit status. A
    SIGINT or SIGTERM (roslaunch's) ends the group."""
    child = subprocess.Popen(command, start_new_session=True)

    def end(signum, _frame):
        try:
            os.killpg(child.pid, signal.SIGCONT)
            os.killpg(child.pid, signum)
        except ProcessLookupError:  # it ended already
            pass

    signal.signal(signal.SIGINT, end)
    signal.signal(signal.SIGTERM, end)
    while True:
        try:
            return child.wait(timeout=every_s)
        except subprocess.TimeoutExpired:
            pass
        try:
            os.killpg(child.pid, signal.SIGSTOP)
            time.sleep(stop_s)
            os.killpg(child.pid, signal.SIGCONT)
        except ProcessLookupError:  # it ended meanwhile
            return child.wait()


def main():
    args = rospy.myargv(sys.argv)
    stall = None
    if len(args) > 4 and args[2] == '--stall':
        stall = (float(args[3]), float(args[4]))
        args = args[:2] + args[5:]
    if len(args) < 3 or args[2] != '--':
        sys.exit('usage: play_after.py TOPIC [--stall STOP_S EVERY_S] -- PLAY_ARGUMENTS')
    topic, play = args[1], args[3:]
    remaps = [a for a in sys.argv[1:] if ':=' in a]
    rospy.init_node('play_after', anonymous=True)
    came = threading.Event()
    rospy.Subscriber(topic, AnyMsg, lambda _: came.set())
    # Wall time: under use_sim_time the clock stands still until the bag plays.
    if not came.wait(WAIT_S):
        rospy.logfatal('play_after: nothing on %s in %.0f s: the bag is not played', topic, WAIT_S)
        sys.exit(1)
    command = ['rosbag', 'play'] + play + remaps
    if stall:
        sys.exit(play_stalled(command, *stall))
    os.execvp('rosbag', command)


if __name__ == '__main__':
    main()
