"""A bag's scans drawn at the estimate on the map (pf_evaluate's scans.png), where they lie on the
walls when the estimate is right: the moments to draw, the scan of each lidar nearest to each, and
the laser's mounting on the robot, taken up the bag's /tf_static and /tf from the scan's frame."""
import numpy as np

from pf_localization.evaluate_reference import associate
from pf_localization.report_plots import _show_map
from pf_localization.self_assessment import STATE_COLOURS


SCAN_WINDOW_S = 2.0    # s of bag time read around each moment before the whole bag is
MOUNT_SEARCH_S = 60.0  # s of /tf, from the bag's start, searched for the laser's mounting


def _matrix(translation, rotation):
    """A transform's 4 x 4 homogeneous matrix (geometry_msgs Vector3 and Quaternion)."""
    x, y, z, w = rotation.x, rotation.y, rotation.z, rotation.w
    n = x * x + y * y + z * z + w * w
    s = 2.0 / n if n > 0 else 0.0
    m = np.eye(4)
    m[:3, :3] = [[1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
                 [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
                 [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)]]
    m[:3, 3] = translation.x, translation.y, translation.z
    return m


def _mount(parents, frame, base_frame, odom_frame):
    """The sensor frame's pose on the robot as a 4 x 4 matrix, and the robot's frame: up the
    transforms (parents: child -> (parent, matrix)) from `frame` to base_frame when given, else to
    the frame whose parent is odom_frame (the one odometry moves), else to the top. None when
    base_frame is given and not above `frame`."""
    m, f = np.eye(4), frame
    for _ in range(32):
        if f == base_frame or f not in parents or (base_frame is None and parents[f][0] == odom_frame):
            break
        parent, t = parents[f]
        m, f = t @ m, parent
    if base_frame is not None and f != base_frame:
        return None, f
    return m, f


def _mount_resolved(parents, frame, base_frame, odom_frame):
    m, f = _mount(parents, frame, base_frame, odom_frame)
    return m is not None and (f == base_frame or (f in parents and parents[f][0] == odom_frame))


def bag_scan_topics(path):
    """The bag's sensor_msgs/LaserScan topics."""
    import rosbag
    with rosbag.Bag(path) as bag:
        topics = bag.get_type_and_topic_info().topics
    return sorted(t for t, info in topics.items() if info.msg_type == 'sensor_msgs/LaserScan')


def _nearest_scans(bag, topics, stamps):
    """(topic, k) -> (|dt|, message): the scan of each topic whose header stamp is nearest to
    stamps[k] (sorted). Read in a window of bag time around each stamp first (bag time is the
    recording's, within a few ms of the header stamps of most bags), then over the whole bag for
    those not found."""
    import rospy
    best = {}

    def offer(topic, msg, ks):
        if not hasattr(msg, 'ranges'):
            return
        t = msg.header.stamp.to_sec()
        for k in ks:
            dt = abs(stamps[k] - t)
            if (topic, k) not in best or dt < best[(topic, k)][0]:
                best[(topic, k)] = (dt, msg)

    begin, end = bag.get_start_time(), bag.get_end_time()
    for k, t in enumerate(stamps):
        start, stop = (rospy.Time.from_sec(v)
                       for v in (max(begin, t - SCAN_WINDOW_S), min(end, t + SCAN_WINDOW_S)))
        for topic, msg, _ in bag.read_messages(topics=list(topics), start_time=start, end_time=stop):
            offer(topic, msg, [k])
    missing = [k for k in range(len(stamps)) if any((topic, k) not in best for topic in topics)]
    if missing:
        for topic, msg, _ in bag.read_messages(topics=list(topics)):
            offer(topic, msg, missing)
    return best


def _read_parents(bag, frames, base_frame, odom_frame):
    """child -> (parent, 4 x 4 matrix) from /tf_static, then /tf (its first MOUNT_SEARCH_S seconds:
    a mounting on /tf is republished often), until every frame's mounting is resolved."""
    import rospy
    parents = {}
    done = lambda: all(_mount_resolved(parents, f, base_frame, odom_frame) for f in frames)
    tf_end = rospy.Time.from_sec(bag.get_start_time() + MOUNT_SEARCH_S)
    for tf_topic, end in (('/tf_static', None), ('/tf', tf_end)):
        if done():
            break
        for _, msg, _ in bag.read_messages(topics=[tf_topic], end_time=end):
            added = False
            for tr in getattr(msg, 'transforms', []):
                child, parent = tr.child_frame_id.lstrip('/'), tr.header.frame_id.lstrip('/')
                if child and parent and child not in parents:
                    parents[child] = (parent, _matrix(tr.transform.translation, tr.transform.rotation))
                    added = True
            if added and done():
                break
    return parents


def read_bag_scans(path, topics, stamps, base_frame=None, odom_frame='odom'):
    """The scan of each topic nearest (by header stamp) to each of `stamps`, as end points on the
    robot: a list of dicts t (stamp), topic, xy ((N, 2) end points in the robot's frame: valid
    ranges, range_min <= r < range_max, through the laser's mounting from /tf_static or /tf), base
    (the robot's frame). The mounting is read up the transforms from the scan's frame to the
    robot's (base_frame, or the frame odometry moves: the child of odom_frame); a frame with no
    transform up from it is taken as the robot's own. Returns (scans, warnings)."""
    import rosbag
    stamps = np.sort(np.asarray(stamps, dtype=float))
    with rosbag.Bag(path) as bag:
        best = _nearest_scans(bag, topics, stamps) if len(stamps) else {}
        frames = {m.header.frame_id.lstrip('/') for _, m in best.values()}
        parents = _read_parents(bag, frames, base_frame, odom_frame)
    scans, warnings = [], []
    for (topic, k), (_, msg) in sorted(best.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        frame = msg.header.frame_id.lstrip('/')
        mount, base = _mount(parents, frame, base_frame, odom_frame)
        if mount is None:
            warning = 'no transform from %s to %s in the bag: %s drawn at the robot\'s origin' % (
                base_frame, frame, topic)
            if warning not in warnings:
                warnings.append(warning)
            mount, base = np.eye(4), base_frame
        r = np.asarray(msg.ranges, dtype=float)
        a = msg.angle_min + msg.angle_increment * np.arange(len(r))
        ok = np.isfinite(r) & (r >= msg.range_min) & (r < msg.range_max)
        pts = np.c_[r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok]), np.zeros(ok.sum()), np.ones(ok.sum())]
        xy = (mount @ pts.T).T[:, :2]
        scans.append({'t': msg.header.stamp.to_sec(), 'topic': topic, 'xy': xy, 'base': base})
    return scans, warnings


def scan_moments(est, log, count=5):
    """The moments whose scans plot_scans draws: `count` updates evenly over the run and the one
    where the fewest beams fit (if another); without a log, `count` estimates. Dicts t, label,
    fit, state."""
    if log is not None and len(log['t']):
        t = log['t']
        idx = list(np.unique(np.linspace(0, len(t) - 1, min(count, len(t))).round().astype(int)))
        fit = log.get('hit_fraction')
        worst = None
        if fit is not None and np.isfinite(fit).any():
            worst = int(np.nanargmin(fit))
            if worst not in idx:
                idx.append(worst)
        return [{'t': float(t[k]), 'label': 'fewest fit' if k == worst else '',
                 'fit': None if fit is None else float(fit[k]),
                 'state': str(log['state'][k]) if 'state' in log else None} for k in sorted(idx)]
    idx = np.unique(np.linspace(0, len(est) - 1, min(count, len(est))).round().astype(int))
    return [{'t': float(est[k, 0]), 'label': '', 'fit': None, 'state': None} for k in idx]


def plot_scans(path, the_map, est, scans, moments, t0, title):
    """The scans' end points placed at the estimate on the map at a few moments: on the walls when
    the estimate is right."""
    import matplotlib.pyplot as plt
    n = len(moments)
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 4.7 * rows + 0.5), squeeze=False)
    colours = ['tab:red', 'tab:blue', 'tab:purple', 'tab:brown']
    topics = sorted({s['topic'] for s in scans})
    for ax, mo in zip(axes.flat, moments):
        pose, kind = associate(est, np.array([mo['t']]))
        mine = [s for s in scans if abs(s['t'] - mo['t']) < 0.5]
        if kind[0] == 0 or not mine:
            ax.text(0.5, 0.5, 'no estimate or scan at %.1f s' % (mo['t'] - t0), transform=ax.transAxes,
                    ha='center')
            ax.set_axis_off()
            continue
        x, y, yaw = pose[0]
        c, s_ = np.cos(yaw), np.sin(yaw)
        pts = []
        for sc in mine:
            xy = sc['xy']
            w = np.c_[x + c * xy[:, 0] - s_ * xy[:, 1], y + s_ * xy[:, 0] + c * xy[:, 1]]
            pts.append((sc['topic'], w))
        allp = np.vstack([w for _, w in pts] + [np.array([[x, y]])])
        d = np.hypot(allp[:, 0] - x, allp[:, 1] - y)
        half = float(np.clip(np.percentile(d, 95) if len(d) > 1 else 3.0, 2.0, 12.0)) * 1.05
        _show_map(ax, the_map, [x - half, x + half], [y - half, y + half], margin_frac=0.0, min_margin=0.0)
        for topic, w in pts:
            ax.plot(w[:, 0], w[:, 1], '.', color=colours[topics.index(topic) % len(colours)], ms=2.5,
                    label=topic if len(topics) > 1 else 'scan end points')
        ax.arrow(x, y, 0.6 * c, 0.6 * s_, width=0.06, color='tab:green', length_includes_head=True, zorder=5)
        ax.plot(x, y, 'o', color='tab:green', ms=5, zorder=5)
        head = 't=%.1f s' % (mo['t'] - t0)
        if mo['fit'] is not None:
            head += ', %.0f %% fit' % (100 * mo['fit'])
        if mo['state']:
            head += ', %s' % mo['state']
        if mo['label']:
            head += ' (%s)' % mo['label']
        ax.set_title(head, fontsize=9, color=STATE_COLOURS.get(mo['state'], 'k'))
        ax.tick_params(labelsize=7)
        ax.xaxis.label.set_size(8)
        ax.yaxis.label.set_size(8)
    for ax in list(axes.flat)[n:]:
        ax.set_axis_off()
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.suptitle('%s: the scans at the estimate (on the walls when it is right; green: the robot)' % title,
                 fontsize=10)
    if handles:
        fig.legend(handles, labels, loc='lower center', ncol=len(handles), fontsize=8, markerscale=3,
                   frameon=False)
    fig.tight_layout(rect=(0, 0.03, 1, 0.97))
    fig.savefig(path, dpi=100)
    plt.close(fig)
