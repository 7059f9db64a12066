"""Evaluate a pf_localization run against a reference trajectory.

usage: pf_evaluate --traj TRAJ.tum (--bag BAG | --ref REF.tum) [--map MAP.yaml]
                   [--log UPDATES.csv] [--particles PARTICLES.csv|.bin] [--out DIR]
                   [--cov COV.csv] [--ref-std 0] [--lost 0.3] [--max-gap 0.5] [--hold]
                   [--gif-seconds 30] [--hypotheses HYP.csv] [--scan-topic /scan]...

A bag without the reference topic (most bags of a real robot) gets a report all the same, and exit
status 0: in place of the error against a reference, what the filter itself knows (below).

Inputs
  TRAJ.tum   the filter's estimates, one line per scan: t x y z qx qy qz qw (map frame).
  reference  the bag's /ground_truth (geometry_msgs/PoseStamped, header stamps) or a TUM file.
  COV.csv    pf_bag_runner --covariance: t,xx,xy,yy,yawyaw,xyaw,yyaw, the published covariance
             (pf_pose) in force from each stamp on.
  HYP.csv    pf_bag_runner --hypotheses: t,rank,x,y,yaw,weight,std_x,std_y,cov_xy, what pf_hypotheses
             publishes at each filter update (one line per hypothesis, rank 1 the heaviest).

Time association: every reference pose gets the estimate at its stamp, linearly interpolated in
x, y and along the shorter arc in yaw between the two bracketing estimates when both lie within
--max-gap seconds of it; otherwise the newest estimate at or before it within --max-gap (zero-order
hold, which is all --hold uses); an estimate within 0.1 ms counts as exact. References with neither
are unmatched and lower the coverage.

Metrics (DIR/summary.json)
  position error e = |(x, y)_est - (x, y)_ref|: RMSE (the ATE, no alignment: both are map frame),
  median, mean, max; yaw error = |wrap(yaw_est - yaw_ref)|: RMSE and max in degrees;
  convergence time = first matched reference time (relative to the first reference pose) from which
  on every error is <= --lost (null if the last one is not); lost fraction = share of matched
  references with e > --lost; coverage = matched / all references.
  Aligned ATE: the RMSE after the best rigid 2D fit (rotation + translation, no scale; Umeyama
  1991) of the matched estimate positions onto the reference's, with the fit's rotation and
  translation: what is left once a reference turned or shifted against the map is taken out.
  With --cov, the covariance's honesty over the matched references after the first 10 s (as
  off_fraction_after_settle): d^2 = e^T S^-1 e, e = (x, y) error, S = the published xy covariance
  in force at the reference's time (newest row at or before it, within --max-gap) + --ref-std^2 I
  (the reference's own noise); inside_95_percent = share with d^2 <= 5.991 (chi-square, 2 dof:
  95 if honest), NEES mean (2 if honest) and median (2 ln 2 = 1.39 if honest) of the finite d^2.
  A singular S (a degenerate covariance) counts as not covering (d^2 = inf) and is counted.
  With --log, the mean/p95 update CPU time and particle counts from the runner's update log.
  With --hypotheses, whether the true place is among the published hypotheses: the share of the
  updates (with a reference pose within --max-gap, interpolated as above) where one lies within
  1 m of it, over all of them and over those with several hypotheses (while ambiguous), and how
  many hypotheses there were.

What the filter itself knows (DIR/summary.json's self_assessment, with a reference or without),
  from --log: the share of the beams that fit the map at the estimate (the log's hit_fraction:
  mean, median, p5, min, the shares below 75 and 50 %, the verdict's default thresholds); the
  verdict (the log's state: localized / uncertain / lost) over time: its shares of the updates,
  its stretches [state, from, to, updates], when it was localized from to the end, and one line
  that says so; the covariance's size: the larger semi-axis of the 1-sigma position ellipse and
  the yaw std of the published covariance (--cov), else the log's std_x, std_y, std_yaw; the share
  of the beams that saw a change of the map (map_changed_share).

Plots (PNG): trajectory.png (map, estimate, reference; without one, the estimate at each update
coloured by its verdict), error.png (position and yaw error over time, with a reference); with
--log fit.png (the beams that fit, the verdict, the covariance's size over time), spread.png
(particle std dev) and cpu.png (update CPU time, particle count); with --bag and --map scans.png
(the scans of --scan-topic placed at the estimate on the map at five moments and the one with the
fewest beams fitting; the laser's mounting from the bag's /tf_static or /tf, up from the scan's
frame to --base-frame or to the frame odometry moves, the child of --odom-frame);
with --cov nees.png (d^2 over time against the 95 % bound);
with --particles particles.gif (the cloud over the map for the first --gif-seconds).
Exit status: 0 on success, 2 on bad input (missing file, nothing matched).
"""
import argparse
import csv
import json
import os
import sys

import numpy as np

EXACT_S = 1e-4  # estimates this close to a reference stamp count as taken at it
OFF_M = 0.5     # an estimate this far from the reference is "off" (the issue trackers' figure)
SETTLE_S = 10.0  # the start of a run that off_fraction_after_settle leaves out
WRONG_M = 1.0    # "localized" while this far off is confidently wrong
# A hypothesis this close to the reference holds the true place: as WRONG_M, the distance at which
# an estimate stops being a noisy version of the right place (a twin room is 4.75 m away).
HYPOTHESIS_NEAR_M = 1.0
HYP_COLUMNS = ('t', 'rank', 'x', 'y', 'yaw', 'weight', 'std_x', 'std_y')
CHI2_95_2DOF = 5.991  # 95 % quantile of the chi-square distribution with 2 degrees of freedom


class EvalError(Exception):
    """Bad or missing input; main() prints it and exits with status 2."""


class NoReference(EvalError):
    """The bag has no message on the reference topic: run() then reports without a reference."""


# ----------------------------------------------------------------------------------- geometry
def wrap(a):
    """Angle(s) wrapped to [-pi, pi)."""
    return (np.asarray(a, dtype=float) + np.pi) % (2 * np.pi) - np.pi


def quat_yaw(qx, qy, qz, qw):
    return np.arctan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))


# ------------------------------------------------------------------------------------- inputs
def _need_file(path, what):
    if not os.path.isfile(path):
        raise EvalError('%s not found: %s' % (what, path))


def read_tum(path, what='trajectory'):
    """TUM file -> (N, 4) array t, x, y, yaw sorted by time (comments and bad lines skipped)."""
    _need_file(path, what)
    rows = []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if len(fields) != 8 or line.lstrip().startswith('#'):
                continue
            try:
                t, x, y, _, qx, qy, qz, qw = map(float, fields)
            except ValueError:
                continue
            rows.append((t, x, y, quat_yaw(qx, qy, qz, qw)))
    if not rows:
        raise EvalError('%s %s has no poses (expected lines "t x y z qx qy qz qw")' % (what, path))
    a = np.array(rows, dtype=float)
    return a[np.argsort(a[:, 0], kind='stable')]


def read_bag_reference(path, topic='/ground_truth'):
    """A bag's PoseStamped reference topic -> (N, 4) array t (header stamp), x, y, yaw."""
    _need_file(path, 'bag')
    try:
        import rosbag
    except ImportError:
        raise EvalError('cannot import rosbag: run with /usr/bin/python3 (ROS 1 Python) or use --ref')
    with rosbag.Bag(path) as bag:
        topics = bag.get_type_and_topic_info().topics
        if topic not in topics or topics[topic].message_count == 0:
            raise NoReference('bag %s has no %s messages (topics: %s)' % (path, topic, ', '.join(sorted(topics))))
        rows = []
        for _, m, _ in bag.read_messages(topics=[topic]):
            p, q = m.pose.position, m.pose.orientation
            rows.append((m.header.stamp.to_sec(), p.x, p.y, quat_yaw(q.x, q.y, q.z, q.w)))
    a = np.array(rows, dtype=float)
    return a[np.argsort(a[:, 0], kind='stable')]


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


SCAN_WINDOW_S = 2.0
MOUNT_SEARCH_S = 60.0


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


def read_update_log(path):
    """Runner's CSV (t,particles,ess,cpu_ms,mean_beam_likelihood,std_x,std_y,std_yaw,updated,...)
    -> dict column -> float array (state and missing: strings); absent or non-numeric columns are
    simply missing."""
    _need_file(path, 'update log')
    with open(path, newline='') as f:
        rows = list(csv.DictReader(f))
    if not rows or 't' not in rows[0]:
        raise EvalError('update log %s is empty or has no "t" column' % path)
    cols = {}
    for name in rows[0]:
        if name is None:
            continue
        if name.strip() in ('state', 'missing'):  # localized / uncertain / lost; sensor names
            cols[name.strip()] = np.array([(r[name] or '').strip() for r in rows])
            continue
        try:
            cols[name.strip()] = np.array([float(r[name]) if r[name] not in (None, '') else np.nan
                                           for r in rows])
        except ValueError:
            pass
    if 't' not in cols:
        raise EvalError('update log %s: column "t" is not numeric' % path)
    return cols


COV_COLUMNS = ('t', 'xx', 'xy', 'yy', 'yawyaw', 'xyaw', 'yyaw')


def read_columns(path, what, columns):
    """A runner's CSV whose header names `columns` (among others, in any order) -> (N, len(columns))
    array in the order of `columns`, unsorted. Lines that do not parse are skipped."""
    _need_file(path, what)
    with open(path, newline='') as f:
        reader = csv.reader(f)
        header = [h.strip() for h in next(reader, [])]
        missing = [c for c in columns if c not in header]
        if missing:
            raise EvalError('%s %s lacks column(s) %s (expected header %s)'
                            % (what, path, ', '.join(missing), ','.join(columns)))
        idx = [header.index(c) for c in columns]
        rows = []
        for r in reader:
            try:
                rows.append([float(r[i]) for i in idx])
            except (ValueError, IndexError):
                continue
    return np.array(rows, dtype=float).reshape(-1, len(columns))


def read_covariance(path):
    """Runner's covariance CSV (header t,xx,xy,yy,yawyaw,xyaw,yyaw) -> (N, 7) array in that column
    order, sorted by time. Lines that do not parse are skipped; 'nan' is kept (no estimate yet)."""
    a = read_columns(path, 'covariance file', COV_COLUMNS)
    a = a[np.isfinite(a[:, 0])]
    if len(a) == 0:
        raise EvalError('covariance file %s has no rows' % path)
    return a[np.argsort(a[:, 0], kind='stable')]


def read_hypotheses(path):
    """Runner's hypotheses CSV (header t,rank,x,y,yaw,weight,std_x,std_y[,cov_xy]) -> (N, 9) array
    in that column order, sorted by time then rank; cov_xy is 0 where the file has none (older
    runners). Lines that do not parse are skipped."""
    with open(path, newline='') as f:
        header = [h.strip() for h in next(csv.reader(f), [])] if os.path.isfile(path) else []
    columns = HYP_COLUMNS + (('cov_xy',) if 'cov_xy' in header else ())
    a = read_columns(path, 'hypotheses file', columns)
    if a.shape[1] == len(HYP_COLUMNS):
        a = np.hstack([a, np.zeros((len(a), 1))])
    a = a[np.isfinite(a[:, 0])]
    if len(a) == 0:
        raise EvalError('hypotheses file %s has no rows' % path)
    return a[np.lexsort((a[:, 1], a[:, 0]))]


def inside_ellipse(hyp, x, y, quantile=CHI2_95_2DOF):
    """Whether (x, y) lies inside each hypothesis's position ellipse of that chi-square quantile
    (rows as read_hypotheses gives them); False where the covariance is degenerate."""
    dx, dy = x - hyp[:, 2], y - hyp[:, 3]
    sxx, syy, sxy = hyp[:, 6] ** 2, hyp[:, 7] ** 2, hyp[:, 8]
    det = sxx * syy - sxy * sxy
    ok = det > 1e-18
    safe = np.where(ok, det, 1.0)
    nees = (syy * dx * dx - 2.0 * sxy * dx * dy + sxx * dy * dy) / safe
    return ok & (nees <= quantile)


def hypotheses_metrics(hyp, ref, max_gap=0.5, interpolate=True, near=HYPOTHESIS_NEAR_M):
    """Whether the reference pose is among each update's hypotheses: within `near` m of one's mean
    or inside its 95 % position ellipse (a place the cloud holds is a spread, not a point: an
    aisle-long cluster holds every pose along the aisle). The share within `near` m alone is
    reported too. Updates without a reference pose within max_gap are left out (and counted)."""
    times, first = np.unique(hyp[:, 0], return_index=True)
    counts = np.diff(np.append(first, len(hyp)))
    truth, kind = associate(ref, times, max_gap, interpolate)
    matched = kind > 0
    contains = np.zeros(len(times), dtype=bool)
    close = np.zeros(len(times), dtype=bool)
    for k in np.flatnonzero(matched):
        rows = hyp[first[k]:first[k] + counts[k]]
        close[k] = bool(np.any(np.hypot(rows[:, 2] - truth[k, 0], rows[:, 3] - truth[k, 1]) <= near))
        contains[k] = close[k] or bool(np.any(inside_ellipse(rows, truth[k, 0], truth[k, 1])))
    several = matched & (counts > 1)
    share = lambda hit, mask: float(np.mean(hit[mask])) if mask.any() else None
    return {
        'updates': int(len(times)), 'updates_matched': int(matched.sum()),
        'contain_truth_share': share(contains, matched),
        'near_truth_share': share(close, matched),
        'updates_with_several': int(several.sum()),
        'contain_truth_share_with_several': share(contains, several),
        'most_hypotheses': int(counts.max()),
        'mean_hypotheses': float(counts.mean()),
        'misses_s': [float(t - ref[0, 0]) for t in times[matched & ~contains]],
        'near_m': float(near),
    }


def read_particles(path):
    """Particle dump -> (N, 4) array t, x, y, yaw. CSV lines t,x,y,yaw (a header line is allowed)
    or, for a .bin file, little-endian float64 records (t, x, y, yaw)."""
    _need_file(path, 'particle dump')
    if path.endswith('.bin'):
        a = np.fromfile(path, dtype='<f8')
        a = a[:len(a) // 4 * 4].reshape(-1, 4)
    else:
        with open(path) as f:
            first = f.readline()
        try:
            [float(v) for v in first.split(',')]
            skip = 0
        except ValueError:
            skip = 1
        a = np.loadtxt(path, delimiter=',', skiprows=skip, usecols=(0, 1, 2, 3), ndmin=2)
    if len(a) == 0:
        raise EvalError('particle dump %s is empty' % path)
    return a[np.argsort(a[:, 0], kind='stable')]


def read_pnm(path):
    """Binary PGM (P5) / PPM (P6) -> (h, w) float array in [0, 1]; colour channels are averaged
    as map_server does."""
    with open(path, 'rb') as f:
        data = f.read()
    tokens, pos = [], 0
    while len(tokens) < 4:
        while pos < len(data) and data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b'#':
            pos = data.index(b'\n', pos)
            continue
        end = pos
        while end < len(data) and not data[end:end + 1].isspace():
            end += 1
        tokens.append(data[pos:end])
        pos = end
    magic, w, h, maxval = tokens[0], int(tokens[1]), int(tokens[2]), int(tokens[3])
    if magic not in (b'P5', b'P6'):
        raise EvalError('%s: not a binary PGM/PPM (magic %r)' % (path, magic))
    ch = 3 if magic == b'P6' else 1
    dtype = '>u2' if maxval > 255 else 'u1'
    px = np.frombuffer(data, dtype=dtype, count=w * h * ch, offset=pos + 1).reshape(h, w, ch)
    return px.astype(float).mean(axis=2) / maxval


def _map_yaml(yaml_path, what):
    """A map_server YAML -> (its fields, the path of its image, which must exist)."""
    _need_file(yaml_path, what + ' YAML')
    import yaml
    with open(yaml_path) as f:
        info = yaml.safe_load(f)
    try:
        image = os.path.join(os.path.dirname(os.path.abspath(yaml_path)), info['image'])
    except (KeyError, TypeError) as e:
        raise EvalError('%s YAML %s lacks image (%s)' % (what, yaml_path, e))
    _need_file(image, what + ' image')
    return info, image


def read_map(yaml_path):
    """map_server YAML + image -> (grey image for display, extent [x0, x1, y0, y1] in m).
    Occupied (p > occupied_thresh) is dark, free (p < free_thresh) white, the rest grey."""
    info, image = _map_yaml(yaml_path, 'map')
    try:
        res, origin = float(info['resolution']), [float(v) for v in info['origin']]
    except (KeyError, TypeError, ValueError) as e:
        raise EvalError('map YAML %s lacks image/resolution/origin (%s)' % (yaml_path, e))
    if image.lower().endswith(('.pgm', '.ppm', '.pnm')):
        v = read_pnm(image)
    else:  # map_server also accepts PNG etc.; Pillow reads those
        from PIL import Image
        v = np.asarray(Image.open(image).convert('L'), dtype=float) / 255.0
    occ = v if int(info.get('negate', 0)) else 1.0 - v
    grey = np.full(occ.shape, 0.72)
    grey[occ > float(info.get('occupied_thresh', 0.65))] = 0.15
    grey[occ < float(info.get('free_thresh', 0.196))] = 1.0
    if len(origin) > 2 and abs(origin[2]) > 1e-9:
        print('pf_evaluate: warning: map origin yaw %.3f ignored in plots' % origin[2], file=sys.stderr)
    h, w = grey.shape
    return grey, [origin[0], origin[0] + w * res, origin[1], origin[1] + h * res]


# The map's changes layer (pf_bag_runner --changes, pf_map_changes) and the true change mask
# (pf_simulator --change-mask) as images: one pixel value per kind of cell.
CHANGE_ADDED, CHANGE_REMOVED, CHANGE_AS_MAPPED, CHANGE_UNSEEN = 0, 205, 254, 128


def read_change_image(yaml_path):
    """A changes layer or a change mask (map_server pair) -> (h, w) uint8 pixels, row 0 the top."""
    _, image = _map_yaml(yaml_path, 'changes')
    return np.rint(read_pnm(image) * 255).astype(np.uint8)


def _near(cells, radius=1):
    """Cells within `radius` cells (8-neighbourhood steps) of a True cell."""
    out = cells.copy()
    h, w = cells.shape
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            src = cells[max(0, -dy):h - max(0, dy), max(0, -dx):w - max(0, dx)]
            out[max(0, dy):h - max(0, -dy), max(0, dx):w - max(0, -dx)] |= src
    return out


def change_metrics(layer, mask=None):
    """How the changes layer compares with the truth. Without a mask: how much of what the lidar saw
    it marks changed. With the true mask: precision (marked cells within one cell of a true change
    of their kind: a beam's end point lies in the cell before a face as often as in the face's) and
    recall (true changes the lidar saw, i.e. that the layer has any evidence of, with a marked cell
    of their kind within one cell), per kind and overall."""
    seen = layer != CHANGE_UNSEEN
    marked = {'added': layer == CHANGE_ADDED, 'removed': layer == CHANGE_REMOVED}
    n_seen = int(seen.sum())
    m = {'cells_seen': n_seen, 'cells_added': int(marked['added'].sum()),
         'cells_removed': int(marked['removed'].sum())}
    m['changed_share_of_seen'] = (m['cells_added'] + m['cells_removed']) / n_seen if n_seen else 0.0
    if mask is None:
        return m
    if mask.shape != layer.shape:
        raise EvalError('the changes layer is %dx%d cells, the mask %dx%d: not the same map'
                        % (layer.shape[1], layer.shape[0], mask.shape[1], mask.shape[0]))
    truth = {'added': mask == CHANGE_ADDED, 'removed': mask == CHANGE_REMOVED}
    tp = found = n_marked = n_true = 0
    for kind in ('added', 'removed'):
        k_tp = int((marked[kind] & _near(truth[kind])).sum())
        k_true = truth[kind] & seen
        k_found = int((k_true & _near(marked[kind])).sum())
        k_marked, k_n_true = int(marked[kind].sum()), int(k_true.sum())
        m[kind] = {'precision': k_tp / k_marked if k_marked else None,
                   'recall': k_found / k_n_true if k_n_true else None,
                   'true_cells_seen': k_n_true}
        tp, found, n_marked, n_true = tp + k_tp, found + k_found, n_marked + k_marked, n_true + k_n_true
    m['precision'] = tp / n_marked if n_marked else None
    m['recall'] = found / n_true if n_true else None
    m['true_cells_seen'] = n_true
    return m


# ------------------------------------------------------------------------------------ metrics
def associate(est, ref_t, max_gap=0.5, interpolate=True):
    """Estimate (x, y, yaw) at each reference time.
    Returns (poses (N, 3) with NaN rows for unmatched references, kind (N,) with
    0 unmatched, 1 exact, 2 interpolated, 3 held)."""
    et = est[:, 0]
    n = len(ref_t)
    poses, kind = np.full((n, 3), np.nan), np.zeros(n, dtype=int)
    for k, t in enumerate(ref_t):
        i = int(np.searchsorted(et, t, side='right')) - 1          # newest at or before t
        j = i + 1                                                  # first after t
        if j < len(et) and et[j] - t <= EXACT_S and (i < 0 or et[j] - t < t - et[i]):
            poses[k], kind[k] = est[j, 1:], 1
        elif i >= 0 and t - et[i] <= EXACT_S:
            poses[k], kind[k] = est[i, 1:], 1
        elif interpolate and i >= 0 and j < len(et) and t - et[i] <= max_gap and et[j] - t <= max_gap:
            s = (t - et[i]) / (et[j] - et[i])
            a, b = est[i, 1:], est[j, 1:]
            poses[k] = (a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]),
                        wrap(a[2] + s * wrap(b[2] - a[2])))
            kind[k] = 2
        elif i >= 0 and t - et[i] <= max_gap:
            poses[k], kind[k] = est[i, 1:], 3
    return poses, kind


def convergence_time(times, errors, lost, t0):
    """Time (relative to t0) of the first sample from which on all errors are <= lost, else None."""
    bad = np.nonzero(np.asarray(errors) > lost)[0]
    if len(bad) == 0:
        return float(times[0] - t0)
    if bad[-1] == len(errors) - 1:
        return None
    return float(times[bad[-1] + 1] - t0)


def rigid_fit(src, dst):
    """The rotation (rad) and translation (2,) that best map the points src (N, 2) onto dst (N, 2)
    in the least-squares sense, no scale: Umeyama (1991) / Horn (1987) in 2D, where the rotation
    has a closed form: atan2 of the summed cross and dot products of the centred pairs."""
    src, dst = np.asarray(src, dtype=float), np.asarray(dst, dtype=float)
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - ms, dst - md
    angle = float(np.arctan2(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]), np.sum(a * b)))
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return angle, md - rot @ ms


def rigid_move(xy, angle, shift):
    """The points xy (N, 2) turned by angle (rad) about the origin, then shifted by shift (2,)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.c_[c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]] + shift


def aligned_ate(est_xy, ref_xy):
    """ATE RMSE after rigid_fit of the estimates onto the reference: (rmse, angle rad, (tx, ty))."""
    angle, shift = rigid_fit(est_xy, ref_xy)
    moved = rigid_move(est_xy, angle, shift)
    return float(np.sqrt(np.mean(np.sum((moved - ref_xy) ** 2, axis=1)))), angle, shift


def evaluate(est, ref, max_gap=0.5, lost=0.3, interpolate=True):
    """est, ref: (N, 4) arrays t, x, y, yaw. Returns (metrics dict, per-match dict of arrays)."""
    if len(est) == 0:
        raise EvalError('the trajectory is empty')
    if len(ref) == 0:
        raise EvalError('the reference is empty')
    poses, kind = associate(est, ref[:, 0], max_gap, interpolate)
    ok = kind > 0
    if not ok.any():
        raise EvalError('no estimate matched a reference pose within %.3g s (estimates %.3f..%.3f s, '
                        'reference %.3f..%.3f s)' % (max_gap, est[0, 0], est[-1, 0], ref[0, 0], ref[-1, 0]))
    t, r, p = ref[ok, 0], ref[ok, 1:], poses[ok]
    pos = np.hypot(p[:, 0] - r[:, 0], p[:, 1] - r[:, 1])
    yaw = np.abs(wrap(p[:, 2] - r[:, 2]))
    t0 = float(ref[0, 0])
    aligned, angle, shift = aligned_ate(p[:, :2], r[:, :2])
    m = {
        'n_reference': int(len(ref)), 'n_matched': int(ok.sum()),
        'n_exact': int((kind == 1).sum()), 'n_interpolated': int((kind == 2).sum()),
        'n_held': int((kind == 3).sum()),
        'coverage': float(ok.mean()),
        'ate_rmse_m': float(np.sqrt(np.mean(pos ** 2))), 'median_m': float(np.median(pos)),
        'mean_m': float(np.mean(pos)), 'max_m': float(np.max(pos)),
        'ate_aligned_rmse_m': aligned, 'aligned_rotation_deg': float(np.degrees(angle)),
        'aligned_translation_m': [float(shift[0]), float(shift[1])],
        'yaw_rmse_deg': float(np.degrees(np.sqrt(np.mean(yaw ** 2)))),
        'yaw_max_deg': float(np.degrees(np.max(yaw))),
        'convergence_time_s': convergence_time(t, pos, lost, t0),
        'lost_fraction': float(np.mean(pos > lost)),
        # The share of the run (after its first SETTLE_S seconds, which a
        # global localization may need) spent more than OFF_M off.
        'off_fraction_after_settle': float(np.mean(pos[t - t0 >= SETTLE_S] > OFF_M))
        if np.any(t - t0 >= SETTLE_S) else None,
        'off_threshold_m': OFF_M, 'settle_s': SETTLE_S,
        'lost_threshold_m': lost, 'max_gap_s': max_gap,
        'association': 'interpolate' if interpolate else 'hold',
        'reference_start_s': t0, 'reference_duration_s': float(ref[-1, 0] - ref[0, 0]),
        'n_estimates': int(len(est)),
    }
    match = {'t': t, 'est': p, 'ref': r, 'pos_err': pos, 'yaw_err': yaw, 'matched': ok,
             'ref_t': ref[:, 0], 'unmatched_t': ref[~ok, 0], 't0': t0, 'alignment': (angle, shift)}
    return m, match


def covariance_at(cov, t, max_gap=0.5):
    """The xy covariance rows (N, 3: xx, xy, yy) in force at the times t: the newest row at or
    before each (one within EXACT_S after it counts as at it), at most max_gap before; NaN rows
    where none is."""
    ct = cov[:, 0]
    out = np.full((len(t), 3), np.nan)
    for k, tk in enumerate(t):
        i = int(np.searchsorted(ct, tk + EXACT_S, side='right')) - 1
        if i >= 0 and tk - ct[i] <= max_gap:
            out[k] = cov[i, 1:4]
    return out


def mahalanobis_sq(err, s_xy, ref_std=0.0):
    """d^2 = e^T S^-1 e for each (x, y) error e (N, 2), S = [[xx, xy], [xy, yy]] from s_xy (N, 3)
    + ref_std^2 I. Returns (d2, degenerate): a non-finite or numerically singular S (determinant
    <= 1e-12 of xx * yy, or a non-positive variance) gives d2 = inf and degenerate True."""
    xx, xy, yy = (s_xy[:, i] + (ref_std ** 2 if i != 1 else 0.0) for i in range(3))
    det = xx * yy - xy * xy
    with np.errstate(invalid='ignore'):
        degenerate = ~(np.isfinite(det) & (xx > 0) & (yy > 0) & (det > 1e-12 * xx * yy))
    ex, ey = err[:, 0], err[:, 1]
    d2 = np.full(len(err), np.inf)
    ok = ~degenerate
    d2[ok] = (yy[ok] * ex[ok] ** 2 - 2 * xy[ok] * ex[ok] * ey[ok] + xx[ok] * ey[ok] ** 2) / det[ok]
    return d2, degenerate


def covariance_metrics(cov, match, max_gap=0.5, ref_std=0.0, aligned=False):
    """How honest the published covariance is, over the matched references after the first
    SETTLE_S seconds (the samples of off_fraction_after_settle). With aligned, the errors are
    measured after the rigid fit onto the reference (for a reference whose frame is turned from
    the map's, which no covariance of a pose on the map should cover). Returns (the summary's
    "covariance" dict, per-sample dict t, d2, degenerate for the plot)."""
    t = match['t']
    s_xy = covariance_at(cov, t, max_gap)
    has = np.all(np.isfinite(s_xy), axis=1)
    use = has & (t - match['t0'] >= SETTLE_S)
    est = match['est'][:, :2]
    if aligned:
        angle, shift = match['alignment']
        est = rigid_move(est, angle, shift)
        # The covariance turns with the estimate.
        c, s = np.cos(angle), np.sin(angle)
        xx, xy, yy = s_xy[:, 0], s_xy[:, 1], s_xy[:, 2]
        s_xy = np.c_[c * c * xx - 2 * c * s * xy + s * s * yy,
                     c * s * (xx - yy) + (c * c - s * s) * xy,
                     s * s * xx + 2 * c * s * xy + c * c * yy]
    err = est - match['ref'][:, :2]
    d2, degenerate = mahalanobis_sq(err[use], s_xy[use], ref_std)
    finite = d2[np.isfinite(d2)]
    c = {
        'samples': int(use.sum()), 'degenerate': int(degenerate.sum()),
        'without_covariance': int((~has & (t - match['t0'] >= SETTLE_S)).sum()),
        'inside_95_percent': float(100.0 * np.mean(d2 <= CHI2_95_2DOF)) if use.any() else None,
        'nees_mean': float(finite.mean()) if len(finite) else None,
        'nees_median': float(np.median(finite)) if len(finite) else None,
        'chi2_95': CHI2_95_2DOF, 'after_s': SETTLE_S, 'ref_std_m': float(ref_std),
        'after_rigid_fit': bool(aligned),
    }
    return c, {'t': t[use], 'd2': d2, 'degenerate': degenerate, 't0': match['t0']}


def confidently_wrong(log, match, max_gap=0.5):
    """Updates whose state was "localized" while the estimate was more than WRONG_M off: the
    error users fear most. Each log row is compared with the matched reference pose nearest in
    time (within max_gap). Returns (count, times relative to the reference start)."""
    if 'state' not in log or len(match['t']) == 0:
        return None, []
    t, err = match['t'], match['pos_err']
    times = []
    for lt, state in zip(log['t'], log['state']):
        if state != 'localized':
            continue
        k = int(np.clip(np.searchsorted(t, lt), 1, len(t) - 1))
        k = k - 1 if abs(t[k - 1] - lt) <= abs(t[k] - lt) else k
        if abs(t[k] - lt) <= max_gap and err[k] > WRONG_M:
            times.append(float(lt - match['t0']))
    return len(times), times


def log_metrics(log):
    """Summary figures of the runner's update log."""
    m = {'n_log_rows': int(len(log['t']))}
    if 'cpu_ms' in log:
        c = log['cpu_ms'][np.isfinite(log['cpu_ms'])]
        if len(c):
            m.update(cpu_ms_mean=float(c.mean()), cpu_ms_p95=float(np.percentile(c, 95)),
                     cpu_ms_max=float(c.max()), cpu_s_total=float(c.sum() / 1000.0))
        if 'updated' in log:
            u = log['cpu_ms'][(log['updated'] > 0) & np.isfinite(log['cpu_ms'])]
            m['n_updates'] = int(len(u))
            if len(u):
                m['cpu_ms_mean_updated'] = float(u.mean())
    if 'particles' in log:
        m.update(particles_mean=float(np.nanmean(log['particles'])),
                 particles_max=int(np.nanmax(log['particles'])))
    if 'ess' in log:
        m['ess_mean'] = float(np.nanmean(log['ess']))
    if 'missing' in log:
        m['sensors_missing'] = missing_sensors(log)
    return m


def missing_sensors(log):
    """Each sensor the log names as missing (silent or blocked): its share of the log's rows and the
    stretches it was missing, [from, to] in s since the log's first row."""
    t = log['t'] - log['t'][0] if len(log['t']) else log['t']
    rows = [set(v.split()) for v in log['missing']]
    out = {}
    for name in sorted(set().union(*rows)) if rows else []:
        on = np.array([name in r for r in rows])
        edges = np.flatnonzero(np.diff(np.concatenate(([0], on.astype(int), [0]))))
        out[name] = {'share': float(on.mean()),
                     'stretches_s': [[float(t[a]), float(t[b - 1])] for a, b in zip(edges[::2], edges[1::2])]}
    return out


# What the filter itself knows (no reference needed): the beams that fit the map at the estimate,
# the verdict, the covariance's size, the map's changes.
STATES = ('localized', 'uncertain', 'lost')
STATE_COLOURS = {'localized': 'tab:green', 'uncertain': 'tab:orange', 'lost': 'tab:red'}
# The verdict's default fit thresholds (confidence_localized_hit_fraction, confidence_lost_hit_fraction):
# drawn on the fit plot as guides; the verdict itself is the runner's.
FIT_LOCALIZED = 0.75
FIT_LOST = 0.5


def _stats(v):
    v = np.asarray(v, dtype=float)
    v = v[np.isfinite(v)]
    if not len(v):
        return None
    return {'mean': float(v.mean()), 'median': float(np.median(v)), 'p5': float(np.percentile(v, 5)),
            'p95': float(np.percentile(v, 95)), 'min': float(v.min()), 'max': float(v.max()),
            'last': float(v[-1])}


def verdict_stretches(t, states, t_end=None):
    """The verdict's runs over time: [[state, from, to, updates], ...] with from the first update of
    the run and to the first of the next (the last run's: t_end, or its last update)."""
    out = []
    for tk, st in zip(t, states):
        if out and out[-1][0] == st:
            out[-1][3] += 1
            continue
        if out:
            out[-1][2] = float(tk)
        out.append([str(st), float(tk), float(tk), 1])
    if out:
        out[-1][2] = float(max(t[-1], t_end if t_end is not None else t[-1]))
    return out


def verdict_judgement(v):
    """One line on the verdict's timeline (the summary's "verdict" dict)."""
    n, runs = v['updates'], v['stretches_s']
    if v['localized_throughout']:
        return 'localized throughout (all %d updates)' % n
    if v['first_localized_s'] is None:
        return 'never localized (%d updates)' % n
    if v['localized_from_s'] is None:
        return 'not localized at the end: %s since %.1f s (localized first at %.1f s)' % (
            runs[-1][0], runs[-1][1], v['first_localized_s'])
    before = runs[:-1]
    if not any(r[0] == 'localized' for r in before):
        if n - v['localized_final_updates'] == 1:
            return 'localized at every update but the first (%s), from %.1f s to the end' % (
                before[0][0], v['localized_from_s'])
        return 'localized from %.1f s to the end (the last %d of %d updates)' % (
            v['localized_from_s'], v['localized_final_updates'], n)
    out = [r for r in before if r[0] != 'localized']
    return 'localized at the end (since %.1f s); before, %d stretch%s not localized: %s' % (
        v['localized_from_s'], len(out), 'es' if len(out) > 1 else '',
        ', '.join('%s %.1f s (%d update%s)' % (st, sum(r[2] - r[1] for r in out if r[0] == st),
                                              sum(r[3] for r in out if r[0] == st),
                                              '' if sum(r[3] for r in out if r[0] == st) == 1 else 's')
                  for st in STATES if any(r[0] == st for r in out)))


def covariance_size(log=None, cov=None):
    """The covariance's size over time: (t, position std (m), yaw std (rad)), from the published
    covariance (cov rows) when given: the larger semi-axis of the 1-sigma position ellipse; else
    from the update log's estimate: the larger of std_x and std_y. None when neither has it."""
    if cov is not None and len(cov):
        xx, xy, yy = cov[:, 1], cov[:, 2], cov[:, 3]
        major = 0.5 * (xx + yy) + np.sqrt(np.maximum(0.25 * (xx - yy) ** 2 + xy * xy, 0.0))
        return cov[:, 0], np.sqrt(np.maximum(major, 0.0)), np.sqrt(np.maximum(cov[:, 4], 0.0)), \
            'published covariance (pf_pose)'
    if log is not None and 'std_x' in log and 'std_y' in log:
        yaw = log['std_yaw'] if 'std_yaw' in log else np.full(len(log['t']), np.nan)
        return log['t'], np.maximum(log['std_x'], log['std_y']), yaw, 'the estimate (update log)'
    return None


def self_assessment(log, t0, t_end=None, cov=None):
    """What the filter says of itself over the run, from the runner's update log: the share of the
    beams that fit the map at the estimate (hit_fraction), the verdict (state) over time, the
    covariance's size (covariance_size), the share of the beams that saw a change of the map.
    Times relative to t0. Empty when the log has none of them."""
    t = log['t'] - t0
    out = {'updates': int(len(t))}
    if 'hit_fraction' in log:
        fit = log['hit_fraction']
        out['fit'] = _stats(fit)
        if out['fit'] is not None:
            ok = np.isfinite(fit)
            out['fit'].update(below_localized_share=float(np.mean(fit[ok] < FIT_LOCALIZED)),
                              below_lost_share=float(np.mean(fit[ok] < FIT_LOST)),
                              localized_guide=FIT_LOCALIZED, lost_guide=FIT_LOST)
    if 'state' in log and len(t):
        states = log['state']
        stretches = verdict_stretches(t, states, None if t_end is None else t_end - t0)
        loc = states == 'localized'
        final = stretches[-1]
        v = {'updates': int(len(t)),
             'shares': {s: float(np.mean(states == s)) for s in STATES},
             'first_localized_s': float(t[np.argmax(loc)]) if loc.any() else None,
             'localized_from_s': final[1] if final[0] == 'localized' else None,
             'localized_final_updates': int(len(t) - np.flatnonzero(~loc)[-1] - 1) if (~loc).any()
             else int(len(t)),
             'localized_throughout': bool(loc.all()),
             'left_localized': int(np.sum(loc[:-1] & ~loc[1:])),
             'final_state': final[0], 'stretches_s': stretches}
        v['judgement'] = verdict_judgement(v)
        out['verdict'] = v
    size = covariance_size(log, cov)
    if size is not None:
        _, pos, yaw, source = size
        out['covariance_size'] = {'source': source, 'position_std_m': _stats(pos),
                                  'yaw_std_deg': _stats(np.degrees(yaw))}
    if 'map_changed_share' in log:
        out['map_changed_beams'] = _stats(log['map_changed_share'])
    return out


# -------------------------------------------------------------------------------------- plots
def _relative(t, t0):
    """Times relative to the reference start; a log on another clock is made relative to itself."""
    t = np.asarray(t, dtype=float)
    return t - t0 if len(t) and abs(t[0] - t0) < 3600 else t - (t[0] if len(t) else 0)


def _break_gaps(a, factor=10.0):
    """Copy of a (t, ...) array with NaN rows inserted where the time step exceeds factor x median,
    so that plotted lines do not bridge gaps in the data."""
    if len(a) < 3:
        return a
    dt = np.diff(a[:, 0])
    cut = np.nonzero(dt > factor * max(np.median(dt), 1e-6))[0] + 1
    return np.insert(a, cut, np.nan, axis=0)


def _show_map(ax, the_map, xs, ys, margin_frac=0.1, min_margin=0.5):
    """Draw the map (if any) and crop the view to the points xs, ys plus a margin."""
    if the_map is not None:
        ax.imshow(the_map[0], cmap='gray', vmin=0, vmax=1, extent=the_map[1], origin='upper',
                  interpolation='nearest', zorder=0)
    x0, x1, y0, y1 = np.nanmin(xs), np.nanmax(xs), np.nanmin(ys), np.nanmax(ys)
    mg = max(min_margin, margin_frac * max(x1 - x0, y1 - y0))
    ax.set_xlim(x0 - mg, x1 + mg)
    ax.set_ylim(y0 - mg, y1 + mg)
    ax.set_aspect('equal')
    ax.set_xlabel('x (m, map frame)')
    ax.set_ylabel('y (m, map frame)')


def plot_trajectory(path, est, ref, the_map, title, log=None):
    """The estimate over the map, with the reference when there is one; without one, the estimate at
    each update coloured by the verdict (the log's state)."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 7))
    has_ref = ref is not None and len(ref) > 0
    both = np.r_[est, ref] if has_ref else est
    # Without a reference, a wider view: the walls around the track are what a reader checks it by.
    _show_map(ax, the_map, both[:, 1], both[:, 2], min_margin=0.5 if has_ref else 2.0)
    e = _break_gaps(est)
    if has_ref:
        r = _break_gaps(ref)
        ax.plot(r[:, 1], r[:, 2], '-', color='tab:green', lw=1.6, label='reference')
        ax.plot(e[:, 1], e[:, 2], '-', color='tab:red', lw=1.0, alpha=0.85, label='estimate')
        ax.plot(ref[0, 1], ref[0, 2], 'o', color='tab:green', ms=7, label='reference start')
        ax.plot(est[0, 1], est[0, 2], 'x', color='tab:red', ms=8, mew=2, label='estimate start')
    else:
        ax.plot(e[:, 1], e[:, 2], '-', color='tab:blue', lw=1.0, alpha=0.85, label='estimate')
        ax.plot(est[0, 1], est[0, 2], 'x', color='tab:blue', ms=8, mew=2, label='estimate start')
        if log is not None and 'state' in log:
            poses, kind = associate(est, log['t'])
            for st in STATES:
                on = (log['state'] == st) & (kind > 0)
                if on.any():
                    ax.plot(poses[on, 0], poses[on, 1], 'o', color=STATE_COLOURS[st], ms=3.5,
                            label='update: %s (%d)' % (st, on.sum()))
    ax.set_title(title)
    ax.legend(loc='best', fontsize=8, framealpha=0.85)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_errors(path, m, match, title):
    import matplotlib.pyplot as plt
    # one sample per reference pose, NaN where unmatched, so lines break at coverage gaps
    t = match['ref_t'] - match['t0']
    pos, yaw = np.full(len(t), np.nan), np.full(len(t), np.nan)
    pos[match['matched']], yaw[match['matched']] = match['pos_err'], np.degrees(match['yaw_err'])
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    a1.plot(t, pos, '.-', color='tab:blue', ms=3, lw=0.8, label='position error')
    a1.axhline(m['lost_threshold_m'], color='tab:red', ls='--', lw=1,
               label='lost threshold %.2f m' % m['lost_threshold_m'])
    if m['convergence_time_s'] is not None:
        for a in (a1, a2):
            a.axvline(m['convergence_time_s'], color='tab:purple', ls=':', lw=1.2)
        a1.plot([], [], color='tab:purple', ls=':', label='converged %.1f s' % m['convergence_time_s'])
    if len(match['unmatched_t']):
        a1.plot(match['unmatched_t'] - match['t0'], np.zeros(len(match['unmatched_t'])), '|',
                color='grey', ms=8, label='unmatched reference (%d)' % len(match['unmatched_t']))
    a1.set_ylabel('position error (m)')
    a1.set_ylim(bottom=0)
    a1.set_title('%s: ATE RMSE %.3f m, yaw RMSE %.2f deg' % (title, m['ate_rmse_m'], m['yaw_rmse_deg']))
    a1.legend(loc='upper right', fontsize=8)
    a2.plot(t, yaw, '.-', color='tab:orange', ms=3, lw=0.8, label='|yaw error|')
    a2.set_ylabel('yaw error (deg)')
    a2.set_xlabel('time since first reference pose (s)')
    a2.set_ylim(bottom=0)
    a2.legend(loc='upper right', fontsize=8)
    for a in (a1, a2):
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_nees(path, c, samples, title):
    """d^2 of every covariance sample over time on a log axis, with the 95 % bound; degenerate
    covariances (d^2 = inf) as triangles on the axis's top."""
    import matplotlib.pyplot as plt
    t, d2 = samples['t'] - samples['t0'], samples['d2']
    fin = np.isfinite(d2)
    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.semilogy(t[fin], np.maximum(d2[fin], 1e-6), '.', color='tab:blue', ms=3, label='d$^2$ = e$^T$ S$^{-1}$ e')
    ax.axhline(CHI2_95_2DOF, color='tab:red', ls='--', lw=1, label='95 %% bound (%.3f)' % CHI2_95_2DOF)
    ax.axhline(2.0, color='tab:green', ls=':', lw=1, label='consistent mean (2)')
    top = max(10 * CHI2_95_2DOF, float(d2[fin].max()) * 2 if fin.any() else 0.0)
    if (~fin).any():
        ax.plot(t[~fin], np.full(int((~fin).sum()), top), 'v', color='tab:purple', ms=6,
                label='degenerate S (%d)' % (~fin).sum())
    inside = c['inside_95_percent']
    ax.set_title('%s: %s inside the 95 %% ellipse, NEES mean %s (after the first %.0f s)'
                 % (title, '-' if inside is None else '%.1f %%' % inside,
                    '-' if c['nees_mean'] is None else '%.2f' % c['nees_mean'], c['after_s']))
    ax.set_xlabel('time since first reference pose (s)')
    ax.set_ylabel('normalised squared error d$^2$')
    ax.grid(alpha=0.3, which='both')
    ax.legend(loc='upper right', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


TIME_SINCE_REFERENCE = 'time since first reference pose (s)'
TIME_SINCE_ESTIMATE = 'time since the first estimate (s)'


def plot_spread(path, log, t0, title, xlabel=TIME_SINCE_REFERENCE):
    import matplotlib.pyplot as plt
    t = _relative(log['t'], t0)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for name, c in (('std_x', 'tab:blue'), ('std_y', 'tab:green')):
        if name in log:
            a1.plot(t, log[name], color=c, lw=1, label='%s (m)' % name)
    if 'std_yaw' in log:
        a2.plot(t, np.degrees(log['std_yaw']), color='tab:orange', lw=1, label='std_yaw (deg)')
    for a, unit in ((a1, 'm'), (a2, 'deg')):
        v = np.concatenate([l.get_ydata() for l in a.get_lines()]) if a.get_lines() else np.array([])
        v = v[np.isfinite(v) & (v > 0)]
        if len(v) and v.max() / v.min() > 100:
            a.set_yscale('log')
        a.set_ylabel('particle std dev (%s)' % unit)
        a.grid(alpha=0.3)
        if a.get_lines():
            a.legend(loc='upper right', fontsize=8)
        else:
            a.text(0.5, 0.5, 'not in log', transform=a.transAxes, ha='center')
    a1.set_title('%s: particle spread' % title)
    a2.set_xlabel(xlabel)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_changes(path, the_map, changes, mask, title):
    """The map with the changes layer over it: added cells red, removed blue; the true mask's
    changed cells, when given, as a faint outline (orange, cyan) under them."""
    import matplotlib.pyplot as plt
    grey, extent = the_map
    if changes.shape != grey.shape:
        raise EvalError('the changes layer is %dx%d cells, the map %dx%d: not the same map'
                        % (changes.shape[1], changes.shape[0], grey.shape[1], grey.shape[0]))
    rgb = np.repeat(grey[:, :, None], 3, axis=2)
    rgb[changes == CHANGE_UNSEEN] *= 0.85
    if mask is not None:
        rgb[mask == CHANGE_ADDED] = (1.0, 0.75, 0.4)
        rgb[mask == CHANGE_REMOVED] = (0.6, 0.9, 1.0)
    rgb[changes == CHANGE_ADDED] = (0.85, 0.1, 0.1)
    rgb[changes == CHANGE_REMOVED] = (0.1, 0.3, 0.9)
    fig, ax = plt.subplots(figsize=(8, 8 * grey.shape[0] / max(grey.shape[1], 1) + 0.6))
    ax.imshow(rgb, extent=extent, origin='upper', interpolation='nearest')
    ax.set_xlabel('x (m)')
    ax.set_ylabel('y (m)')
    ax.set_title(title + ': where the world no longer matches the map (red added, blue removed%s)'
                 % ('; the truth light' if mask is not None else ''), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_fit(path, log, t0, title, cov=None, xlabel=TIME_SINCE_ESTIMATE):
    """What the filter knows over time: the share of the beams that fit the map at the estimate
    (and of those that saw a change of the map), the verdict, the covariance's size."""
    import matplotlib.pyplot as plt
    t = _relative(log['t'], t0)
    fig, (a1, a2, a3) = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True,
                                     gridspec_kw={'height_ratios': [3, 0.7, 2.2]})
    if 'hit_fraction' in log:
        a1.plot(t, log['hit_fraction'], '.-', color='tab:blue', ms=3, lw=0.8,
                label='beams that fit the map at the estimate')
    if 'map_changed_share' in log and np.nanmax(log['map_changed_share'], initial=0.0) > 0:
        a1.plot(t, log['map_changed_share'], '-', color='tab:grey', lw=0.8,
                label='beams that saw a change of the map')
    a1.axhline(FIT_LOCALIZED, color='tab:green', ls='--', lw=1, label='%.0f %% (localized, default)'
               % (100 * FIT_LOCALIZED))
    a1.axhline(FIT_LOST, color='tab:red', ls='--', lw=1, label='%.0f %% (lost, default)' % (100 * FIT_LOST))
    a1.set_ylim(-0.02, 1.05)
    a1.set_ylabel('share of the beams')
    a1.legend(loc='lower left', fontsize=8, framealpha=0.85)
    a1.set_title('%s: what the filter knows (no reference needed)' % title)
    if 'state' in log and len(t):
        for st, t_from, t_to, _ in verdict_stretches(t, log['state']):
            a2.broken_barh([(t_from, max(t_to - t_from, 1e-3))], (0, 1), color=STATE_COLOURS.get(st, 'grey'))
        from matplotlib.patches import Patch
        a2.plot(t, np.full(len(t), 0.5), '|', color='k', ms=6, alpha=0.4)
        share = lambda st: 100 * np.mean(log['state'] == st)
        a2.legend(handles=[Patch(color=STATE_COLOURS[st], label='%s %.0f %%' % (st, share(st))) for st in STATES],
                  loc='center left', bbox_to_anchor=(1.0, 0.5), fontsize=7, frameon=False,
                  title='of the updates', title_fontsize=7)
    a2.set_yticks([])
    a2.set_ylabel('verdict', rotation=0, ha='right', va='center')
    size = covariance_size(log, cov)
    if size is not None:
        ct, pos, yaw, source = size
        ct = ct - (log['t'][0] - t[0]) if len(t) else _relative(ct, t0)  # on the log's time axis
        h = a3.plot(ct, pos, '-', color='tab:purple', lw=1, label='position std (m)')
        a3.set_ylabel('position std (m)')
        v = pos[np.isfinite(pos) & (pos > 0)]
        if len(v) and v.max() / v.min() > 30:
            a3.set_yscale('log')
        b = a3.twinx()
        h += b.plot(ct, np.degrees(yaw), '-', color='tab:orange', lw=1, label='yaw std (deg)')
        b.set_ylabel('yaw std (deg)')
        b.set_ylim(bottom=0)
        a3.legend(handles=h, loc='upper right', fontsize=8, title='1-sigma, %s' % source, title_fontsize=8)
    else:
        a3.text(0.5, 0.5, 'no covariance in the log', transform=a3.transAxes, ha='center')
    a3.set_xlabel(xlabel)
    for a in (a1, a3):
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


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


def cpu_axis_top(c, percentile=99.0, headroom=1.5):
    """The top of the CPU time axis: all of c when its largest value is within `headroom` x the
    `percentile`th, else that (a few slow updates, e.g. the first, would squash the rest onto the
    axis). None when c has no finite value."""
    c = np.asarray(c, dtype=float)
    c = c[np.isfinite(c)]
    if len(c) == 0:
        return None
    clip = headroom * float(np.percentile(c, percentile))
    return clip if c.max() > clip > 0 else None


def _plot_cpu_times(ax, t, c):
    """The CPU times as dots, with their mean; the few above the axis's top drawn on it as
    triangles and counted in the legend. Returns the legend's handles."""
    handles = ax.plot(t, c, '.', color='tab:blue', ms=3, label='update CPU time')
    if not np.isfinite(c).any():
        return handles
    handles.append(ax.axhline(np.nanmean(c), color='tab:blue', ls='--', lw=1,
                              label='mean %.2f ms' % np.nanmean(c)))
    top = cpu_axis_top(c)
    if top is None:
        ax.set_ylim(bottom=0)
        return handles
    ax.set_ylim(0, top)
    over = np.isfinite(c) & (c > top)
    handles += ax.plot(t[over], np.full(int(over.sum()), top), '^', color='tab:purple', ms=6, clip_on=False,
                       label='%d above %.2f ms (max %.1f ms)' % (over.sum(), top, np.nanmax(c)))
    return handles


def plot_cpu(path, log, t0, title, xlabel=TIME_SINCE_REFERENCE):
    import matplotlib.pyplot as plt
    t = _relative(log['t'], t0)
    fig, ax = plt.subplots(figsize=(9, 4.5))
    handles = []
    if 'cpu_ms' in log:
        handles += _plot_cpu_times(ax, t, log['cpu_ms'])
    ax.set_ylabel('CPU time per update (ms)')
    ax.set_xlabel(xlabel)
    ax.grid(alpha=0.3)
    if 'particles' in log:
        a2 = ax.twinx()
        handles += a2.plot(t, log['particles'], '-', color='tab:red', lw=1, label='particle count')
        a2.set_ylabel('particles')
        a2.set_ylim(bottom=0, top=1.1 * np.nanmax(log['particles']) + 1)
    ax.set_title('%s: update CPU time and particle count' % title)
    if handles:
        ax.legend(handles=handles, loc='upper right', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def make_particle_gif(path, parts, est, ref, the_map, seconds, title, max_frames=60,
                      max_particles=2000):
    """Animated GIF of the particle cloud for the first `seconds` of the dump."""
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter
    times, starts = np.unique(parts[:, 0], return_index=True)
    ends = np.r_[starts[1:], len(parts)]
    sel = np.nonzero(times <= times[0] + seconds)[0]
    sel = sel[np.unique(np.linspace(0, len(sel) - 1, min(max_frames, len(sel))).round().astype(int))]
    rng = np.random.default_rng(0)
    frames = []
    for k in sel:
        idx = np.arange(starts[k], ends[k])
        if len(idx) > max_particles:
            idx = rng.choice(idx, max_particles, replace=False)
        frames.append((times[k], ends[k] - starts[k], parts[idx, 1:3]))
    t_end = times[sel[-1]]
    win = lambda a: a[(a[:, 0] >= times[0] - 1) & (a[:, 0] <= t_end + 1)]
    e, r = win(est), win(ref)
    xs = np.concatenate([f[2][:, 0] for f in frames] + [e[:, 1], r[:, 1]])
    ys = np.concatenate([f[2][:, 1] for f in frames] + [e[:, 2], r[:, 2]])
    fig, ax = plt.subplots(figsize=(4.2, 4.6))
    _show_map(ax, the_map, xs, ys, margin_frac=0.05, min_margin=0.3)
    ax.tick_params(labelsize=7)
    ax.xaxis.label.set_size(8)
    ax.yaxis.label.set_size(8)
    cloud = ax.scatter([], [], s=2.5, c='tab:blue', alpha=0.6, lw=0, label='particles')
    ref_dot, = ax.plot([], [], 'o', color='tab:green', ms=5, label='reference')
    est_dot, = ax.plot([], [], 'x', color='tab:red', ms=6, mew=2, label='estimate')
    handles = [cloud, ref_dot, est_dot] if len(ref) else [cloud, est_dot]
    # Below the axes: inside, wherever it went, the cloud passes under it sooner or later.
    fig.legend(handles=handles, loc='lower center', ncol=len(handles), fontsize=6, markerscale=1.5,
               frameon=False)
    head = ax.set_title('', fontsize=8)

    def near(a, t):
        if len(a) == 0:
            return [], []
        i = int(np.argmin(np.abs(a[:, 0] - t)))
        return ([a[i, 1]], [a[i, 2]]) if abs(a[i, 0] - t) < 1.0 else ([], [])

    def draw(f):
        t, n, xy = f
        cloud.set_offsets(xy)
        ref_dot.set_data(*near(ref, t))
        est_dot.set_data(*near(est, t))
        head.set_text('%s  t=%.1f s  (%d of %d particles)' % (title, t - times[0], len(xy), n))
        return cloud, ref_dot, est_dot, head

    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fps = max(1.0, min(8.0, len(frames) / max(seconds, 1e-3) * 2))
    FuncAnimation(fig, draw, frames=frames, blit=False).save(path, writer=PillowWriter(fps=fps), dpi=96)
    plt.close(fig)
    return len(frames)


# --------------------------------------------------------------------------------------- main
def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0], epilog=__doc__[__doc__.index('Inputs'):],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--traj', required=True, help='estimated trajectory (TUM)')
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument('--bag', help='bag with the reference on --ref-topic')
    g.add_argument('--ref', help='reference trajectory (TUM)')
    p.add_argument('--ref-topic', default='/ground_truth', help='PoseStamped topic in --bag')
    p.add_argument('--map', help='map_server YAML drawn under the trajectories')
    p.add_argument('--log', help="runner's per-update CSV log")
    p.add_argument('--particles', help='particle dump (CSV t,x,y,yaw or .bin float64 records)')
    p.add_argument('--out', help='report directory (default: TRAJ without extension + _eval)')
    p.add_argument('--cov', help="runner's covariance CSV (pf_bag_runner --covariance)")
    p.add_argument('--hypotheses', help="runner's hypotheses CSV (pf_bag_runner --hypotheses)")
    p.add_argument('--changes', help="runner's map changes layer (pf_bag_runner --changes), drawn and "
                   'counted')
    p.add_argument('--change-mask', help='the true change mask (pf_simulator --change-mask) the changes '
                   'layer is scored against')
    p.add_argument('--ref-std', type=float, default=0.0,
                   help="the reference's own position std dev (m), added as ref_std^2 I to the covariance")
    p.add_argument('--cov-aligned', action='store_true',
                   help='judge the covariance on the errors after the rigid fit (a reference turned from the map)')
    p.add_argument('--lost', type=float, default=0.3, help='lost / convergence threshold (m)')
    p.add_argument('--max-gap', type=float, default=0.5, help='max time between reference and estimate (s)')
    p.add_argument('--hold', action='store_true', help='no interpolation: newest estimate at or before')
    p.add_argument('--gif-seconds', type=float, default=30.0, help='length of the particle GIF (s)')
    p.add_argument('--title', help='name used in plot titles (default: the recording\'s name: the --bag '
                                   'or --ref file\'s, without its extension)')
    p.add_argument('--scan-topic', action='append', help="LaserScan topic of --bag whose scans are drawn at the "
                   'estimate (scans.png; once per lidar; default: /scan, else the bag\'s first LaserScan topic)')
    p.add_argument('--base-frame', help="the robot's frame the laser's mounting is read up to (default: the frame "
                   'odometry moves, the child of --odom-frame)')
    p.add_argument('--odom-frame', default='odom', help='the odometry frame (default: odom)')
    p.add_argument('--no-plots', action='store_true', help='only write summary.json')
    return p.parse_args(argv)


def reference_or_none(args):
    """The reference trajectory, or None (with the reason) when --bag has none on --ref-topic."""
    if args.ref:
        return read_tum(args.ref, 'reference'), None
    try:
        return read_bag_reference(args.bag, args.ref_topic), None
    except NoReference:
        import rosbag
        with rosbag.Bag(args.bag) as bag:
            topics = sorted(bag.get_type_and_topic_info().topics)
        return None, 'the bag has no %s; its topics: %s' % (args.ref_topic, ', '.join(topics))


def draw_scans(args, out, est, log, the_map, t0, title, m):
    """scans.png: the scans of --bag at the estimate at a few moments (scan_moments). Returns whether
    it was drawn; what kept it from being drawn, or a mounting not found, goes to m['scans']."""
    try:
        topics = args.scan_topic or [t for t in bag_scan_topics(args.bag) if t == '/scan'] or \
            bag_scan_topics(args.bag)[:1]
    except ImportError:
        m['scans'] = {'drawn': False, 'why': 'cannot import rosbag (run with /usr/bin/python3)'}
        return False
    if not topics:
        m['scans'] = {'drawn': False, 'why': 'no sensor_msgs/LaserScan topic in the bag'}
        return False
    moments = scan_moments(est, log)
    scans, warnings = read_bag_scans(args.bag, topics, [mo['t'] for mo in moments], args.base_frame,
                                     args.odom_frame)
    m['scans'] = {'drawn': bool(scans), 'topics': topics, 'moments_s': [mo['t'] - t0 for mo in moments],
                  'robot_frame': sorted({s['base'] for s in scans if s['base']}), 'warnings': warnings}
    if not scans:
        m['scans']['why'] = 'no scan on %s' % ', '.join(topics)
        return False
    plot_scans(os.path.join(out, 'scans.png'), the_map, est, scans, moments, t0, title)
    return True


def run(args):
    est = read_tum(args.traj)
    ref, no_ref = reference_or_none(args)
    the_map = read_map(args.map) if args.map else None
    log = read_update_log(args.log) if args.log else None
    parts = read_particles(args.particles) if args.particles else None
    cov = read_covariance(args.cov) if args.cov else None
    hyp = read_hypotheses(args.hypotheses) if args.hypotheses else None
    if args.change_mask and not args.changes:
        raise EvalError('--change-mask needs --changes (the layer to score)')
    changes = read_change_image(args.changes) if args.changes else None
    mask = read_change_image(args.change_mask) if args.change_mask else None
    if not (np.isfinite(args.ref_std) and args.ref_std >= 0):
        raise EvalError('--ref-std must be a finite number >= 0, got %g' % args.ref_std)
    out = args.out or os.path.splitext(args.traj)[0] + '_eval'
    os.makedirs(out, exist_ok=True)
    title = args.title or os.path.splitext(os.path.basename(args.bag or args.ref))[0]

    if ref is not None:
        m, match = evaluate(est, ref, args.max_gap, args.lost, not args.hold)
        t0, xlabel = match['t0'], TIME_SINCE_REFERENCE
    else:
        # No reference: what the filter itself knows, on the estimates' time.
        m, match = {'n_estimates': int(len(est)), 'duration_s': float(est[-1, 0] - est[0, 0])}, None
        t0, xlabel = float(est[0, 0]), TIME_SINCE_ESTIMATE
        m['reference'] = {'none': no_ref}
    m['has_reference'] = ref is not None
    if log is not None:
        m.update(log_metrics(log))
        m['self_assessment'] = self_assessment(log, t0, est[-1, 0], cov)
        if match is not None:
            count, times = confidently_wrong(log, match, args.max_gap)
            if count is not None:
                m.update(confidently_wrong_updates=count, confidently_wrong_times_s=times,
                         confidently_wrong_threshold_m=WRONG_M)
    cov_samples = None
    if cov is not None and match is not None:
        m['covariance'], cov_samples = covariance_metrics(cov, match, args.max_gap, args.ref_std,
                                                          args.cov_aligned)
    elif cov is not None:
        m.setdefault('self_assessment', {'updates': 0})
        _, pos, yaw, source = covariance_size(cov=cov)
        m['self_assessment']['covariance_size'] = {'source': source, 'position_std_m': _stats(pos),
                                                   'yaw_std_deg': _stats(np.degrees(yaw))}
    if hyp is not None and ref is not None:
        m['hypotheses'] = hypotheses_metrics(hyp, ref, args.max_gap, not args.hold)
    if changes is not None:
        m['map_changes'] = change_metrics(changes, mask)
    m['inputs'] = {k: os.path.abspath(v) for k, v in (('traj', args.traj), ('bag', args.bag), ('ref', args.ref),
                   ('map', args.map), ('log', args.log), ('particles', args.particles), ('cov', args.cov),
                   ('hypotheses', args.hypotheses), ('changes', args.changes),
                   ('change_mask', args.change_mask)) if v}
    plots = []
    if not args.no_plots:
        import matplotlib
        matplotlib.use('Agg')
        plot_trajectory(os.path.join(out, 'trajectory.png'), est, ref, the_map,
                        title + (': trajectory' if ref is not None else ': track (no reference)'), log)
        plots.append('trajectory.png')
        if match is not None:
            plot_errors(os.path.join(out, 'error.png'), m, match, title)
            plots.append('error.png')
        if log is not None:
            plot_fit(os.path.join(out, 'fit.png'), log, t0, title, cov, xlabel)
            plot_spread(os.path.join(out, 'spread.png'), log, t0, title, xlabel)
            plot_cpu(os.path.join(out, 'cpu.png'), log, t0, title, xlabel)
            plots += ['fit.png', 'spread.png', 'cpu.png']
        if args.bag and the_map is not None and draw_scans(args, out, est, log, the_map, t0, title, m):
            plots.append('scans.png')
        if cov_samples is not None:
            plot_nees(os.path.join(out, 'nees.png'), m['covariance'], cov_samples, title)
            plots.append('nees.png')
        if changes is not None and the_map is not None:
            plot_changes(os.path.join(out, 'changes.png'), the_map, changes, mask, title)
            plots.append('changes.png')
        if parts is not None:
            m['gif_frames'] = make_particle_gif(os.path.join(out, 'particles.gif'), parts, est,
                                                ref if ref is not None else np.zeros((0, 4)), the_map,
                                                args.gif_seconds, title)
            plots.append('particles.gif')
    m['plots'] = plots
    summary = os.path.join(out, 'summary.json')
    with open(summary, 'w') as f:
        json.dump(m, f, indent=2)
        f.write('\n')
    return m, summary


def describe(m, summary):
    if m.get('has_reference', True):
        lines = describe_reference(m)
    else:
        lines = ['pf_evaluate: no reference (%s): the report says what the filter itself knows'
                 % m['reference']['none'],
                 '  track:          %d poses over %.1f s' % (m['n_estimates'], m['duration_s'])]
    lines += describe_self(m.get('self_assessment') or {})
    if 'covariance' in m:
        lines.append(describe_covariance(m['covariance']))
    if 'hypotheses' in m:
        lines.append(describe_hypotheses(m['hypotheses']))
    if 'map_changes' in m:
        lines.append(describe_changes(m['map_changes']))
    for name, v in m.get('sensors_missing', {}).items():
        lines.append('  sensor missing: %s in %.0f %% of the updates (%s s)' % (
            name, 100 * v['share'], ', '.join('%.1f-%.1f' % tuple(x) for x in v['stretches_s'])))
    if 'cpu_ms_mean' in m:
        lines.append('  update CPU:     mean %.2f ms  p95 %.2f ms  (%d log rows)'
                     % (m['cpu_ms_mean'], m['cpu_ms_p95'], m['n_log_rows']))
    for w in m.get('scans', {}).get('warnings', []):
        lines.append('  scans:          %s' % w)
    if m.get('scans') and not m['scans']['drawn']:
        lines.append('  scans:          not drawn: %s' % m['scans'].get('why', '?'))
    lines.append('  report: %s' % summary + (' (+ %s)' % ', '.join(m['plots']) if m['plots'] else ''))
    return '\n'.join(lines)


def describe_reference(m):
    """The text summary's lines on the error against the reference."""
    conv = m['convergence_time_s']
    lines = [
        'pf_evaluate: %d/%d reference poses matched (coverage %.1f %%: %d exact, %d interpolated, %d held)'
        % (m['n_matched'], m['n_reference'], 100 * m['coverage'], m['n_exact'], m['n_interpolated'],
           m['n_held']),
        '  position error: RMSE %.3f m  median %.3f  mean %.3f  max %.3f m'
        % (m['ate_rmse_m'], m['median_m'], m['mean_m'], m['max_m']),
        '  aligned ATE:    RMSE %.3f m after the best rigid fit onto the reference (rotation %.2f deg, '
        'translation %.3f, %.3f m)' % ((m['ate_aligned_rmse_m'], m['aligned_rotation_deg']) + tuple(m['aligned_translation_m'])),
        '  yaw error:      RMSE %.2f deg  max %.2f deg' % (m['yaw_rmse_deg'], m['yaw_max_deg']),
        '  converged:      %s; lost (> %.2f m) %.1f %% of matched poses'
        % ('after %.2f s' % conv if conv is not None else 'never', m['lost_threshold_m'],
           100 * m['lost_fraction']),
    ]
    if m.get('off_fraction_after_settle') is not None:
        lines.append('  off (> %.1f m):  %.1f %% of the run after its first %.0f s'
                     % (m['off_threshold_m'], 100 * m['off_fraction_after_settle'], m['settle_s']))
    if 'confidently_wrong_updates' in m:
        lines.append('  confidently wrong: %d updates "localized" while more than %.0f m off'
                     % (m['confidently_wrong_updates'], m['confidently_wrong_threshold_m']))
    return lines


def describe_self(a):
    """The text summary's lines on what the filter says of itself (self_assessment)."""
    lines = []
    pct = lambda v: '%.1f %%' % (100 * v)
    f = a.get('fit')
    if f:
        lines.append('  beams fit:      mean %s  median %s  p5 %s  min %s of the beams at the estimate; '
                     'below %.0f %% in %s of the updates, below %.0f %% in %s'
                     % (pct(f['mean']), pct(f['median']), pct(f['p5']), pct(f['min']),
                        100 * f['localized_guide'], pct(f['below_localized_share']), 100 * f['lost_guide'],
                        pct(f['below_lost_share'])))
    v = a.get('verdict')
    if v:
        sh = v['shares']
        lines.append('  verdict:        %s; localized in %s of %d updates, uncertain %s, lost %s'
                     % (v['judgement'], pct(sh['localized']), v['updates'], pct(sh['uncertain']),
                        pct(sh['lost'])))
        runs = v['stretches_s']
        one = lambda r: '%s %.1f-%.1f s (%d update%s)' % (tuple(r) + ('' if r[3] == 1 else 's',))
        text = ', '.join(one(r) for r in runs[:8])
        if len(runs) > 8:
            text += ', ... (%d stretches; the last: %s)' % (len(runs), one(runs[-1]))
        lines.append('  timeline:       %s' % text)
    c = a.get('covariance_size')
    if c and c['position_std_m']:
        p, y = c['position_std_m'], c['yaw_std_deg']
        lines.append('  covariance size: 1-sigma position median %.3f m, p95 %.3f, max %.3f, last %.3f m; '
                     'yaw median %.2f deg, max %.2f deg (%s)'
                     % (p['median'], p['p95'], p['max'], p['last'], y['median'] if y else float('nan'),
                        y['max'] if y else float('nan'), c['source']))
    ch = a.get('map_changed_beams')
    if ch and ch['max'] > 0:
        lines.append('  beams on map changes: mean %s, max %s of the beams per update'
                     % (pct(ch['mean']), pct(ch['max'])))
    return lines


def describe_hypotheses(h):
    """The text summary's hypotheses line."""
    pct = lambda v: '-' if v is None else '%.1f %%' % (100 * v)
    return ('  hypotheses:     the true place within %.1f m of one or inside its 95 %% ellipse in %s '
            'of %d updates (within %.1f m: %s); in %s of the %d with several (up to %d, mean %.2f)'
            % (h['near_m'], pct(h['contain_truth_share']), h['updates_matched'], h['near_m'],
               pct(h.get('near_truth_share')), pct(h['contain_truth_share_with_several']),
               h['updates_with_several'], h['most_hypotheses'], h['mean_hypotheses']))


def describe_changes(c):
    """The text summary's map changes line."""
    text = ('  map changes:    %.2f %% of the %d cells seen marked changed (%d added, %d removed)'
            % (100 * c['changed_share_of_seen'], c['cells_seen'], c['cells_added'], c['cells_removed']))
    if 'recall' in c:
        fmt = lambda v: '-' if v is None else '%.3f' % v
        text += ('; against the true mask: precision %s, recall %s of %d changed cells seen '
                 '(added %s / %s, removed %s / %s; within one cell)'
                 % (fmt(c['precision']), fmt(c['recall']), c['true_cells_seen'],
                    fmt(c['added']['precision']), fmt(c['added']['recall']),
                    fmt(c['removed']['precision']), fmt(c['removed']['recall'])))
    return text


def describe_covariance(c):
    """The text summary's covariance line."""
    if not c['samples']:
        return '  covariance:     no matched pose with a covariance after the first %.0f s' % c['after_s']
    fmt = lambda v: '-' if v is None else '%.2f' % v
    return ('  covariance:     %.1f %% of %d poses after the first %.0f s inside the 95 %% ellipse '
            '(honest: 95); NEES mean %s, median %s (honest: 2, 1.39); %d degenerate; ref std %.3f m'
            % (c['inside_95_percent'], c['samples'], c['after_s'], fmt(c['nees_mean']),
               fmt(c['nees_median']), c['degenerate'], c['ref_std_m'])
            + (', after the rigid fit' if c.get('after_rigid_fit') else ''))


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        m, summary = run(args)
    except (EvalError, OSError) as e:
        print('pf_evaluate: error: %s' % e, file=sys.stderr)
        return 2
    print(describe(m, summary))
    return 0


if __name__ == '__main__':
    sys.exit(main())
