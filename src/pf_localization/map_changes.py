"""The map's changes layer (pf_bag_runner --changes, pf_map_changes) read as an image and scored:
how much of what the lidar saw it marks changed and, against the true change mask (pf_simulator
--change-mask), precision and recall per kind within one cell; and the text summary's line."""
import numpy as np

from pf_localization.evaluate_inputs import EvalError, _map_yaml, read_pnm


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
