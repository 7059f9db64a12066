"""pf_tune's search space and the params files it writes: SPACE.yaml read and checked against the base
parameters, a trial's point drawn from it (or the baseline's, clamped into it), and a params file with
a point's values put into the base file's text, its comments kept."""
import os

import yaml


# The default search space: the motion model's alphas, the likelihood field's hit model, the
# likelihood exponent, the recovery rates and the number of beams.
DEFAULT_SPACE = {
    'odom_alpha1': {'low': 0.005, 'high': 2.0, 'log': True},
    'odom_alpha2': {'low': 0.005, 'high': 2.0, 'log': True},
    'odom_alpha3': {'low': 0.005, 'high': 2.0, 'log': True},
    'odom_alpha4': {'low': 0.005, 'high': 2.0, 'log': True},
    'laser_sigma_hit': {'low': 0.03, 'high': 0.6, 'log': True},
    'laser_z_hit': {'low': 0.5, 'high': 0.99},
    'laser_z_rand': {'low': 0.01, 'high': 0.5, 'log': True},
    'laser_likelihood_exponent': {'low': 0.02, 'high': 1.0, 'log': True},
    'recovery_alpha_slow': {'low': 0.001, 'high': 0.04, 'log': True},  # below alpha_fast's range:
    'recovery_alpha_fast': {'low': 0.05, 'high': 0.5, 'log': True},   # the runner needs fast > slow
    'laser_max_beams': {'low': 20, 'high': 180, 'step': 10, 'type': 'int'},
}


class TuneError(Exception):
    """Bad input; main() prints it and exits with status 2."""


# ------------------------------------------------------------------------- the search space
def load_space(path, base):
    """SPACE.yaml -> {name: {'low', 'high', 'log', 'step', 'type'}}, checked against the base params."""
    if path is None:
        raw = DEFAULT_SPACE
        where = 'the default space'
    else:
        if not os.path.isfile(path):
            raise TuneError('space file not found: %s' % path)
        try:
            with open(path) as f:
                raw = yaml.safe_load(f)
        except yaml.YAMLError as e:
            raise TuneError('space file %s is not valid YAML: %s' % (path, e))
        where = path
    if not isinstance(raw, dict) or not raw:
        raise TuneError('%s: expected a mapping "parameter: {low: L, high: H[, log: true][, type: int]'
                        '[, step: S]}", got %r' % (where, raw))
    space = {}
    for name, spec in raw.items():
        if name not in base:
            raise TuneError('%s: "%s" is not a parameter of the --params-from file (known: %s)'
                            % (where, name, ', '.join(sorted(k for k, v in base.items()
                                                             if isinstance(v, (int, float))
                                                             and not isinstance(v, bool)))))
        if not isinstance(spec, dict) or 'low' not in spec or 'high' not in spec:
            raise TuneError('%s: %s needs "low" and "high", got %r' % (where, name, spec))
        unknown = set(spec) - {'low', 'high', 'log', 'step', 'type'}
        if unknown:
            raise TuneError('%s: %s has unknown key(s) %s (allowed: low, high, log, step, type)'
                            % (where, name, ', '.join(sorted(unknown))))
        kind = spec.get('type', 'int' if isinstance(base[name], int) and not isinstance(base[name], bool)
                        else 'float')
        if kind not in ('int', 'float'):
            raise TuneError('%s: %s: type must be int or float, got %r' % (where, name, kind))
        try:
            low, high = float(spec['low']), float(spec['high'])
        except (TypeError, ValueError):
            raise TuneError('%s: %s: low and high must be numbers, got %r, %r'
                            % (where, name, spec['low'], spec['high']))
        log = bool(spec.get('log', False))
        if not low < high:
            raise TuneError('%s: %s: low (%g) must be below high (%g)' % (where, name, low, high))
        if log and low <= 0:
            raise TuneError('%s: %s: a log scale needs low > 0, got %g' % (where, name, low))
        step = spec.get('step')
        if step is not None and (not isinstance(step, (int, float)) or step <= 0 or log):
            raise TuneError('%s: %s: step must be a positive number and not combined with log' % (where, name))
        if kind == 'int':
            low, high = int(round(low)), int(round(high))
            step = int(step or 1)
        space[name] = {'low': low, 'high': high, 'log': log, 'step': step, 'type': kind}
    return space


def suggest(trial, space):
    p = {}
    for name, s in space.items():
        if s['type'] == 'int':
            p[name] = trial.suggest_int(name, s['low'], s['high'], step=s['step'], log=s['log'])
        else:
            p[name] = trial.suggest_float(name, s['low'], s['high'], step=s['step'], log=s['log'])
    return p


def baseline_point(space, base):
    """The base file's values, clamped into the space (and onto its int step), for trial 0."""
    p = {}
    for name, s in space.items():
        v = min(max(float(base[name]), s['low']), s['high'])
        if s['type'] == 'int':
            v = s['low'] + int(round((v - s['low']) / s['step'])) * s['step']
            v = int(min(v, s['high']))
        p[name] = v
    return p


# ------------------------------------------------------------------------- params files
def format_value(v):
    if isinstance(v, bool):
        return 'true' if v else 'false'
    if isinstance(v, int):
        return str(v)
    return repr(float(v))


def write_params_yaml(base_text, values, path, header=''):
    """The base file's text with each value of `values` put on its key's line (comments kept)."""
    out, seen = [], set()
    for line in base_text.splitlines():
        stripped = line.lstrip()
        key = stripped.split(':', 1)[0].strip() if ':' in stripped and not stripped.startswith('#') else None
        if key in values and line == stripped:  # top-level keys only
            head = '%s: %s' % (key, format_value(values[key]))
            hash_at = line.find('#', len(key) + 1)
            if hash_at >= 0:  # keep the comment, at its column when the new value fits
                line = head.ljust(hash_at - 1) + ' ' + line[hash_at:]
            else:
                line = head
            seen.add(key)
        out.append(line)
    missing = [k for k in values if k not in seen]
    if missing:
        out.append('# set by pf_tune (not in the base file):')
        out += ['%s: %s' % (k, format_value(values[k])) for k in missing]
    with open(path, 'w') as f:
        f.write(header + '\n'.join(out) + '\n')
