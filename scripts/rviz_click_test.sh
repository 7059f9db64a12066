#!/usr/bin/env bash
# The rviz workflow, tested in a real rviz: "2D Pose Estimate" clicked with
# the mouse re-initialises pf_node where the click says.
#
#   bash scripts/rviz_click_test.sh [--out DIR] [--keep]
#
# Needs a built workspace (scripts/build.sh) and, from the "rviz test" group
# of scripts/install_deps.sh: rviz, Xvfb, xdotool, xwininfo (x11-utils) and
# ImageMagick's import. Installs nothing itself. Needs no display: it starts
# its own Xvfb, and its own roscore on a free port, so it can run beside
# anything else.
#
# What it does:
#   1. map_publisher + pf_node with maps/building.yaml, pf_node started
#      deliberately WRONG (in the south-west room, small covariance), and
#      bags/tracking.bag played with --clock at rate 1;
#   2. rviz with a copy of rviz/pf.rviz whose TopDownOrtho camera has a known
#      scale and focal point, so that a pixel of the 3D view and a map point
#      are related by an exact affine map; the 3D view's position on the
#      screen comes from the X window tree (xwininfo);
#   3. after a few seconds the bag is paused (the player's pause_playback
#      service) and DIR/rviz_before.png is taken: map, scan, particle cloud;
#   4. xdotool selects the 2D Pose Estimate tool (its shortcut, "p") and drags
#      from the pixel of the robot's true position towards its true heading;
#   5. a small rospy listener checks that /initialpose arrived within 0.2 m and
#      10 deg of the pose that pixel and drag stand for, that pf_node's next
#      pf_pose and its first filter update once the bag resumes are within
#      0.3 m of it, and prints the distances and heading differences;
#   6. DIR/rviz_after.png. Exits 0 when every check passed, 1 otherwise, 2 when
#      something it needs is missing.
#
# DIR defaults to docs/. Logs of every process are in a temporary folder,
# removed at the end unless --keep (or a failure) says otherwise.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
out=$repo/docs
keep=0
while [ $# -gt 0 ]; do
  case $1 in
    --out) out=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "rviz_click_test: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
# ROS 1 on Debian is Python code for /usr/bin/python3.
export PATH=/usr/bin:$PATH

for tool in rviz Xvfb xdotool xwininfo import; do
  if ! command -v "$tool" > /dev/null; then
    echo "rviz_click_test: '$tool' is missing: bash scripts/install_deps.sh installs it (rviz test group)" >&2
    exit 2
  fi
done
pf_source_workspace "$ws" rviz_click_test || exit 2
mkdir -p "$out"
out=$(cd "$out" && pwd)

# --- The camera: 40 px per m, centred on the middle of the building map ------
# (maps/building.yaml: origin (-1, -1), 440 x 340 cells of 0.05 m).
readonly SCALE=40.0 FOCAL_X=10.0 FOCAL_Y=7.5
readonly SCREEN_W=1280 SCREEN_H=900
# pf_node's deliberately wrong start: the south-west room, facing north.
readonly WRONG_X=4.5 WRONG_Y=3.0 WRONG_A=1.5708
readonly PLAY_BEFORE_PAUSE=6.0  # [s of bag time] before the click

t_start=$(date +%s.%N)
tmp=$(mktemp -d /tmp/rviz_click_test.XXXXXX)
export ROS_HOME=$tmp/ros_home ROS_LOG_DIR=$tmp/ros_log
pids=()
status=1
cleanup() {
  # Every process this script started, by its id, newest first and one at a
  # time: rviz aborts when its X server goes first.
  local i
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    kill -INT "${pids[i]}" 2> /dev/null || continue
    for _ in $(seq 50); do kill -0 "${pids[i]}" 2> /dev/null || break; sleep 0.1; done
    kill -KILL "${pids[i]}" 2> /dev/null || true
  done
  wait 2> /dev/null || true
  if [ "$keep" -eq 1 ] || [ "$status" -ne 0 ]; then
    echo "rviz_click_test: logs in $tmp"
  else
    rm -rf "$tmp"
  fi
}
trap cleanup EXIT
start() {  # start NAME COMMAND...: runs COMMAND in the background, output in $tmp/NAME.log
  local name=$1
  shift
  "$@" > "$tmp/$name.log" 2>&1 &
  pids+=($!)
}
fail() {
  echo "rviz_click_test: FAILED: $*" >&2
  exit 1
}
wait_for() {  # wait_for SECONDS WHAT COMMAND...: polls COMMAND until it succeeds
  local limit=$1 what=$2
  shift 2
  local t0=$SECONDS
  until "$@" > /dev/null 2>&1; do
    [ $((SECONDS - t0)) -lt "$limit" ] || fail "$what (waited $limit s; logs in $tmp)"
    sleep 0.2
  done
}

# --- The helper: the rospy listener, and the pixel <-> map arithmetic --------
cat > "$tmp/helper.py" << 'EOF'
"""rviz_click_test's ROS listener and geometry (run by /usr/bin/python3)."""
import math
import re
import sys
import time


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def pose_of(msg_pose):
    return (msg_pose.position.x, msg_pose.position.y, yaw_of(msg_pose.orientation))


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def diff(a, b):
    """(distance m, |heading difference| deg)"""
    return math.hypot(a[0] - b[0], a[1] - b[1]), abs(math.degrees(wrap(a[2] - b[2])))


def render_window(tree):
    """x y w h of rviz's 3D view: the largest unnamed X window (Ogre's) in xwininfo -tree."""
    best = None
    for m in re.finditer(r'\(has no name\): \(\)\s+(\d+)x(\d+)\+-?\d+\+-?\d+\s+\+(-?\d+)\+(-?\d+)', tree):
        w, h, x, y = map(int, m.groups())
        if best is None or w * h > best[2] * best[3]:
            best = (x, y, w, h)
    if best is None or best[2] < 200 or best[3] < 200:
        return None
    return best


def wait(cond, timeout, step=0.05):
    t0 = time.time()
    while not cond():
        if time.time() - t0 > timeout:
            return False
        time.sleep(step)
    return True


class Listener:
    def __init__(self):
        import rospy
        from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
        self.rospy = rospy
        rospy.init_node('rviz_click_listener', anonymous=True, disable_signals=True)
        self.truth = None
        self.initialpose = None
        self.poses = []  # (wall time received, pf_pose message)
        rospy.Subscriber('/ground_truth', PoseStamped, self._truth)
        rospy.Subscriber('/initialpose', PoseWithCovarianceStamped, self._initialpose)
        rospy.Subscriber('/pf_pose', PoseWithCovarianceStamped, self._pf_pose)

    def _truth(self, msg):
        self.truth = msg

    def _initialpose(self, msg):
        if self.initialpose is None:
            self.initialpose = (time.time(), msg)

    def _pf_pose(self, msg):
        self.poses.append((time.time(), msg))

    def pause(self, paused):
        from std_srvs.srv import SetBool
        self.rospy.wait_for_service('/player/pause_playback', timeout=10.0)
        self.rospy.ServiceProxy('/player/pause_playback', SetBool)(paused)


def phase_before(play_s):
    """Lets the bag play play_s seconds, pauses it; prints the truth then, and how wrong pf_node is."""
    ln = Listener()
    if not wait(lambda: ln.truth is not None, 60.0):
        sys.exit('no /ground_truth within 60 s: is the bag playing?')
    t0 = ln.truth.header.stamp.to_sec()
    if not wait(lambda: ln.truth.header.stamp.to_sec() - t0 >= play_s - 1.0 and ln.poses, 60.0):
        sys.exit('no pf_pose from pf_node within 60 s')
    ln.pause(True)
    time.sleep(0.5)  # what was on the way arrives
    truth = pose_of(ln.truth.pose)
    est = pose_of(ln.poses[-1][1].pose.pose)
    d, a = diff(est, truth)
    print('%.4f %.4f %.4f %.3f %.1f' % (truth + (d, a)))


def phase_click(expected):
    """Checks the /initialpose of the click, pf_node's answer, and its first update once the bag resumes."""
    ln = Listener()
    print('listening', flush=True)
    failures = []
    if not wait(lambda: ln.initialpose is not None, 30.0):
        sys.exit('FAILED: no /initialpose within 30 s of the click: the drag did not reach rviz\'s tool')
    t_ip, ip = ln.initialpose
    ip_pose = pose_of(ip.pose.pose)
    d, a = diff(ip_pose, expected)
    print('/initialpose        x=%.3f y=%.3f yaw=%.3f  frame %s; cov xx=%.3f yy=%.3f aa=%.4f'
          % (ip_pose + (ip.header.frame_id, ip.pose.covariance[0], ip.pose.covariance[7], ip.pose.covariance[35])))
    print('clicked pose        x=%.3f y=%.3f yaw=%.3f  (from the pixel and the drag)' % expected)
    print('  /initialpose vs clicked pose: %.3f m, %.1f deg (limits 0.2 m, 10 deg)' % (d, a))
    if not (d <= 0.2 and a <= 10.0):
        failures.append('/initialpose is %.3f m / %.1f deg from the clicked pose' % (d, a))
    if ip.header.frame_id not in ('map', '/map'):
        failures.append('/initialpose is in frame %r, not map' % ip.header.frame_id)

    # pf_node answers the /initialpose at once, so its pf_pose can reach this
    # listener before the listener's own copy of the /initialpose does (a
    # loaded machine: CI saw it): poses received up to 1 s before count, the
    # stamp says which came after it.
    def first_pose(pred):
        found = [m for r, m in ln.poses if r >= t_ip - 1.0 and pred(m)]
        return found[0] if found else None

    stamp = ip.header.stamp
    if not wait(lambda: first_pose(lambda m: m.header.stamp >= stamp) is not None, 10.0):
        failures.append('pf_node published no pf_pose within 10 s of the /initialpose')
        next_pose = None
    else:
        next_pose = pose_of(first_pose(lambda m: m.header.stamp >= stamp).pose.pose)
        d, a = diff(next_pose, ip_pose)
        print('pf_pose next        x=%.3f y=%.3f yaw=%.3f' % next_pose)
        print('  distance %.3f m, heading difference %.1f deg from the clicked pose (limit 0.3 m)' % (d, a))
        if d > 0.3:
            failures.append('pf_node\'s next pf_pose is %.3f m from the clicked pose' % d)
    ln.pause(False)
    if not wait(lambda: first_pose(lambda m: m.header.stamp > stamp) is not None, 15.0):
        failures.append('no pf_pose from a filter update within 15 s of resuming the bag')
    else:
        upd = first_pose(lambda m: m.header.stamp > stamp)
        upd_pose = pose_of(upd.pose.pose)
        d, a = diff(upd_pose, ip_pose)
        print('pf_pose updated     x=%.3f y=%.3f yaw=%.3f  (first scan after resuming, %.2f s later)'
              % (upd_pose + ((upd.header.stamp - stamp).to_sec(),)))
        print('  distance %.3f m, heading difference %.1f deg from the clicked pose (limit 0.3 m)' % (d, a))
        if ln.truth is not None:
            print('  and %.3f m, %.1f deg from the ground truth' % diff(upd_pose, pose_of(ln.truth.pose)))
        if d > 0.3:
            failures.append('pf_node\'s first update after the click is %.3f m from the clicked pose' % d)
    time.sleep(3.0)  # a few more updates, for the "after" screenshot
    if failures:
        print('FAILED: ' + '; '.join(failures))
        sys.exit(1)
    print('PASSED')


if __name__ == '__main__':
    cmd = sys.argv[1]
    if cmd == 'render_window':
        r = render_window(sys.stdin.read())
        if r is None:
            sys.exit(1)
        print('%d %d %d %d' % r)
    elif cmd == 'before':
        phase_before(float(sys.argv[2]))
    elif cmd == 'click':
        phase_click(tuple(float(v) for v in sys.argv[2:5]))
    else:
        sys.exit('unknown command ' + cmd)
EOF
helper() { /usr/bin/python3 "$tmp/helper.py" "$@"; }

# --- X server, ROS master, the demo ----------------------------------------
exec 3> "$tmp/display"
start xvfb Xvfb -displayfd 3 -screen 0 "${SCREEN_W}x${SCREEN_H}x24" -nolisten tcp
exec 3>&-
wait_for 10 "Xvfb did not start" test -s "$tmp/display"
export DISPLAY=:$(head -n 1 "$tmp/display")

port=$(pf_free_port) || exit 2
export ROS_MASTER_URI=http://localhost:$port
start roscore roscore -p "$port"
wait_for 30 "roscore did not start" rosparam get /rosdistro
rosparam set /use_sim_time true

start map_publisher rosrun pf_localization map_publisher "$repo/maps/building.yaml"
rosparam load "$repo/config/pf.yaml" /pf_node
rosparam set /pf_node/initial_pose_x "$WRONG_X"
rosparam set /pf_node/initial_pose_y "$WRONG_Y"
rosparam set /pf_node/initial_pose_a "$WRONG_A"
# A small covariance, so that the filter cannot find the truth by itself.
rosparam set /pf_node/initial_cov_xx 0.0025
rosparam set /pf_node/initial_cov_yy 0.0025
rosparam set /pf_node/initial_cov_aa 0.0012
# And no filter update before the click but the first: recovery (random
# particles once the wrong start turns "lost") found the robot within the
# 6 s before the click in 2 runs of 2. The updates come back right after the
# click, through dynamic_reconfigure, as a user would tune them.
readonly HELD_UPDATE_MIN_D=4.0 HELD_UPDATE_MIN_A=6.0  # within the sliders (cfg/PfLocalization.cfg)
rosparam set /pf_node/update_min_d "$HELD_UPDATE_MIN_D"
rosparam set /pf_node/update_min_a "$HELD_UPDATE_MIN_A"
start pf_node rosrun pf_localization pf_node

# A copy of rviz/pf.rviz with the camera fixed, the window filling the screen
# and only the Displays and Tool Properties panels (without a saved window
# state, Qt puts every panel in the left dock, and the Time panel's width
# then leaves the 3D view no room).
/usr/bin/python3 - "$repo/rviz/pf.rviz" "$tmp/test.rviz" "$SCALE" "$FOCAL_X" "$FOCAL_Y" "$SCREEN_W" "$SCREEN_H" << 'EOF'
import sys
import yaml
src, dst, scale, fx, fy, w, h = sys.argv[1:]
c = yaml.safe_load(open(src))
c['Panels'] = [p for p in c['Panels'] if p['Class'] in ('rviz/Displays', 'rviz/Tool Properties')]
view = c['Visualization Manager']['Views']['Current']
assert view['Class'] == 'rviz/TopDownOrtho', view['Class']
view.update({'Scale': float(scale), 'X': float(fx), 'Y': float(fy), 'Angle': 0.0})
c['Preferences']['PromptSaveOnExit'] = False
c['Window Geometry'].update({'X': 0, 'Y': 0, 'Width': int(w), 'Height': int(h)})
yaml.safe_dump(c, open(dst, 'w'), default_flow_style=False, sort_keys=False)
EOF
start rviz rviz -d "$tmp/test.rviz"
render_window() { xwininfo -root -tree | helper render_window; }
wait_for 60 "rviz's 3D view did not appear" render_window
read -r RX RY RW RH < <(render_window)
echo "rviz_click_test: rviz's 3D view is ${RW}x${RH} at (${RX}, ${RY}) on a ${SCREEN_W}x${SCREEN_H} screen (DISPLAY $DISPLAY)"
sleep 2  # the map and the first particle cloud arrive

start player rosbag play --clock -r 1 "$repo/bags/tracking.bag" __name:=player
read -r TX TY TA WRONG_D WRONG_DEG < <(helper before "$PLAY_BEFORE_PAUSE") || fail "no estimate before the click"
echo "rviz_click_test: bag paused; the robot is at x=$TX y=$TY yaw=$TA, pf_node's estimate is $WRONG_D m / $WRONG_DEG deg off"
awk -v d="$WRONG_D" 'BEGIN { exit !(d > 0.5) }' ||
  fail "pf_node was only $WRONG_D m off before the click: the test would prove nothing"
sleep 1.5  # rviz draws the last scan
import -window root "$out/rviz_before.png"

# --- The click -------------------------------------------------------------
# Pixel (px, py) of the 3D view <-> map (x, y): x = FOCAL_X + (px - w/2) / SCALE,
# y = FOCAL_Y - (py - h/2) / SCALE (rviz casts the ray through the pixel's
# corner, px / w of the way across). The press is at the robot's true
# position; the drag goes 80 px towards its true heading.
read -r PX PY QX QY EX EY EA < <(/usr/bin/python3 - "$TX" "$TY" "$TA" "$RX" "$RY" "$RW" "$RH" "$SCALE" "$FOCAL_X" "$FOCAL_Y" << 'EOF'
import math
import sys
tx, ty, ta, rx, ry, rw, rh, s, fx, fy = map(float, sys.argv[1:])
px = round(rw / 2 + (tx - fx) * s)
py = round(rh / 2 - (ty - fy) * s)
qx = px + round(80 * math.cos(ta))
qy = py - round(80 * math.sin(ta))
ex = fx + (px - rw / 2) / s
ey = fy - (py - rh / 2) / s
ea = math.atan2(-(qy - py), qx - px)
print(int(rx + px), int(ry + py), int(rx + qx), int(ry + qy), '%.4f %.4f %.4f' % (ex, ey, ea))
EOF
)
echo "rviz_click_test: dragging from screen pixel ($PX, $PY) to ($QX, $QY): the pose x=$EX y=$EY yaw=$EA"
helper click "$EX" "$EY" "$EA" > "$tmp/listener.out" 2>&1 &
listener=$!
pids+=($listener)
wait_for 20 "the listener did not start" grep -q listening "$tmp/listener.out"
sleep 0.5
# The 3D view takes the keyboard when the pointer enters it; "p" is the
# shortcut of the 2D Pose Estimate tool.
xdotool mousemove "$((RX + RW / 2))" "$((RY + 20))"
sleep 0.3
xdotool key p
sleep 0.3
xdotool mousemove "$PX" "$PY"
sleep 0.2
xdotool mousedown 1
sleep 0.2
for f in 0.25 0.5 0.75 1.0; do  # Qt needs motion events to turn the arrow
  xdotool mousemove "$(awk -v a="$PX" -v b="$QX" -v f=$f 'BEGIN { printf "%d", a + (b - a) * f }')" \
    "$(awk -v a="$PY" -v b="$QY" -v f=$f 'BEGIN { printf "%d", a + (b - a) * f }')"
  sleep 0.1
done
xdotool mouseup 1
# The filter's own update thresholds again (config/pf.yaml's), for the updates after the click.
read -r MIN_D MIN_A < <(/usr/bin/python3 -c 'import sys, yaml; c = yaml.safe_load(open(sys.argv[1])); print(c["update_min_d"], c["update_min_a"])' "$repo/config/pf.yaml")
rosrun dynamic_reconfigure dynparam set /pf_node "{update_min_d: $MIN_D, update_min_a: $MIN_A}" > "$tmp/dynparam.out" 2>&1 &
listener_status=0
wait "$listener" || listener_status=$?
sed 's/^/  /' "$tmp/listener.out"
import -window root "$out/rviz_after.png"

elapsed=$(awk -v a="$t_start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.0f", b - a }')
echo "rviz_click_test: screenshots $out/rviz_before.png and $out/rviz_after.png; took $elapsed s"
[ "$listener_status" -eq 0 ] || fail "see the listener's output above"
status=0
echo "rviz_click_test: PASSED"
