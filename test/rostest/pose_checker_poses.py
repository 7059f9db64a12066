"""pose_checker's planar poses: (x, y, yaw) tuples from ROS messages, their composition and the
position and yaw errors between two of them."""
import math

from geometry_msgs.msg import Quaternion


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def quat_from_yaw(yaw):
    return Quaternion(0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def compose(a, b):
    """(x, y, yaw) a * b."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap(a[2] + b[2]))


def pose2_of_transform(t):
    return (t.transform.translation.x, t.transform.translation.y, yaw_of(t.transform.rotation))


def pose2_of_pose(p):
    return (p.position.x, p.position.y, yaw_of(p.orientation))


def pos_err(a, b):
    return math.hypot(a[0] - b[0], a[1] - b[1])


def yaw_err_deg(a, b):
    return abs(math.degrees(wrap(a[2] - b[2])))
