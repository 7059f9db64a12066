#!/usr/bin/python3
"""rosbag play, started once a latched topic has a message: for a rostest
whose bag needs something another node of the launch publishes first:
pf_node's first pf_pose (sent once its map is set up and its cloud spread,
before any scan), or a laser's mounting on /tf_static. A fixed delay (play
-d) is not enough on a loaded machine, where starting the launch's nodes and
building the map's fields can take longer than the bag needs to move the
robot away from its initial pose, or into the checker's window.

    <node pkg="pf_localization" type="play_after.py" name="player"
          args="TOPIC -- PLAY_ARGUMENTS"/>

Waits for TOPIC (any type) up to 60 s of wall time, then becomes rosbag play
with PLAY_ARGUMENTS (and roslaunch's remappings); exits 1 if nothing came."""

import os
import sys
import threading

import rospy
from rospy import AnyMsg

WAIT_S = 60.0


def main():
    args = rospy.myargv(sys.argv)
    if len(args) < 3 or args[2] != '--':
        sys.exit('usage: play_after.py TOPIC -- PLAY_ARGUMENTS')
    topic, play = args[1], args[3:]
    remaps = [a for a in sys.argv[1:] if ':=' in a]
    rospy.init_node('play_after', anonymous=True)
    came = threading.Event()
    rospy.Subscriber(topic, AnyMsg, lambda _: came.set())
    # Wall time: under use_sim_time the clock stands still until the bag plays.
    if not came.wait(WAIT_S):
        rospy.logfatal('play_after: nothing on %s in %.0f s: the bag is not played', topic, WAIT_S)
        sys.exit(1)
    os.execvp('rosbag', ['rosbag', 'play'] + play + remaps)


if __name__ == '__main__':
    main()
