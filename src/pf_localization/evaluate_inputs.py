"""pf_evaluate's inputs read into arrays: the filter's trajectory and a reference (TUM files, a bag's
PoseStamped topic), the runner's update log, covariance, hypotheses and particle dumps, and a
map_server map. Bad or missing input raises EvalError, which names what is wrong and where."""
import csv
import os
import sys

import numpy as np


class EvalError(Exception):
    """Bad or missing input; main() prints it and exits with status 2."""


class NoReference(EvalError):
    """The bag has no message on the reference topic: run() then reports without a reference."""


def quat_yaw(qx, qy, qz, qw):
    return np.arctan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))


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


HYP_COLUMNS = ('t', 'rank', 'x', 'y', 'yaw', 'weight', 'std_x', 'std_y')


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
