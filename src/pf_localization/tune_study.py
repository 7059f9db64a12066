"""pf_tune's Optuna study: its trials run batch by batch on Dask (resumed from its storage, refused
when it was set up differently), then the lowest trials confirmed with more seeds and the one that
replaces the baseline chosen (pf_tune --help, "Choosing the best")."""
import math
import os
import sys

import numpy as np

from pf_localization.tune_space import TuneError, baseline_point, suggest
from pf_localization.tune_tasks import jobs_for, run_jobs


def study_signature(setup, args):
    return {'bags': setup['bags'], 'objective': setup['objective'], 'fit_distance': args.fit_distance,
            'space': {k: [v['low'], v['high'], v['log'], v['type']] for k, v in setup['space'].items()},
            'seed': args.seed, 'params_from': os.path.abspath(args.params_from),
            **({'sensors': (args.scan_topic or []) + (args.cloud_topic or [])}
               if args.scan_topic or args.cloud_topic else {})}


def tune(args, setup, client, say=print):
    import optuna
    from optuna.trial import TrialState
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    storage = args.storage or 'sqlite:///%s' % os.path.join(os.path.abspath(args.out), 'study.db')
    sig = study_signature(setup, args)
    existing = [s.study_name for s in optuna.study.get_all_study_summaries(storage)]
    resumed = args.study_name in existing
    if resumed:
        study = optuna.load_study(study_name=args.study_name, storage=storage)
        old = study.user_attrs.get('signature')
        if old is not None and old != sig:
            diff = [k for k in sig if sig[k] != old.get(k)]
            raise TuneError('study "%s" in %s was set up differently (%s differ): use another --out, '
                            '--storage or --study-name' % (args.study_name, storage, ', '.join(diff)))
    # A resumed study draws on with another seed, so that it does not repeat its first random points.
    n_before = len(optuna.load_study(study_name=args.study_name, storage=storage).trials) if resumed else 0
    sampler = optuna.samplers.TPESampler(seed=args.seed + n_before)
    study = optuna.create_study(study_name=args.study_name, storage=storage, sampler=sampler,
                                direction='minimize', load_if_exists=True)
    if not resumed:
        study.set_user_attr('signature', sig)
        study.enqueue_trial(baseline_point(setup['space'], setup['base']))
    # Trials left running by an interrupted pf_tune: failed, and their points evaluated again.
    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        study.tell(t.number, state=TrialState.FAIL)
        study.enqueue_trial(t.params)
        say('pf_tune: trial %d was interrupted: it is run again' % (t.number + 1))
    done = len(study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,)))
    say('pf_tune: study "%s" in %s: %s, %d of %d trials done' % (args.study_name, storage,
                                                                'resumed' if resumed else 'new', done, args.trials))
    bar = None
    if not args.no_progress:
        from tqdm import tqdm
        bar = tqdm(total=args.trials, initial=done, desc='pf_tune', unit='trial', file=sys.stderr,
                   dynamic_ncols=True)
        if done:
            bar.set_postfix_str('best %.4f (trial %d)' % (study.best_value, study.best_trial.number + 1))
    write = bar.write if bar else say
    while done < args.trials:
        trials = [study.ask() for _ in range(min(args.batch, args.trials - done))]
        points = [suggest(t, setup['space']) for t in trials]
        jobs = [j for pt in points for j in jobs_for(setup, args, pt)]
        results = run_jobs(client, jobs, write)
        nb = len(setup['bags'])
        for k, t in enumerate(trials):
            rs = results[k * nb:(k + 1) * nb]
            for r in rs:
                if not r['ok']:
                    write('pf_tune: trial %d: %s failed: %s' % (t.number + 1, os.path.basename(r['bag']),
                                                                r.get('error')))
            value = float(np.mean([r['score'] for r in rs]))
            t.set_user_attr('bags', [{k2: r.get(k2) for k2 in ('bag', 'ok', 'score', 'metrics', 'error',
                                                              'wall_s', 'host')} for r in rs])
            study.tell(t, value)
            done += 1
            if bar:
                bar.update(1)
                bar.set_postfix_str('best %.4f (trial %d)' % (study.best_value, study.best_trial.number + 1))
            else:
                say('pf_tune: trial %d: %.4f (best %.4f, trial %d)' % (t.number + 1, value, study.best_value,
                                                                         study.best_trial.number + 1))
    if bar:
        bar.close()
    return study


def choose(baseline, candidates, min_gain):
    """The trial that replaces the baseline, or None. baseline: the baseline's values, one per seed;
    candidates: {trial number: values, one per seed}. The candidate with the lowest mean wins if its
    mean is below the baseline's by more than min_gain and by more than twice the standard error of
    the difference (each mean's error from its seeds' spread; one seed has no spread). Returns
    (number or None, {number or 'baseline': (mean, standard error)}, the verdict as a sentence)."""
    def mean_se(v):
        v = np.asarray(v, dtype=float)
        return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else 0.0
    stats = {'baseline': mean_se(baseline)}
    stats.update({k: mean_se(v) for k, v in candidates.items()})
    if not candidates:
        return None, stats, 'no other trial completed: the baseline is kept'
    best = min(candidates, key=lambda k: (stats[k][0], k))
    (mb, sb), (mc, sc) = stats['baseline'], stats[best]
    gain, noise = mb - mc, 2.0 * math.hypot(sb, sc)
    if gain > min_gain and gain > noise:
        return best, stats, ('trial %d beats the baseline by %.4g, more than --min-gain %g and twice the '
                             'standard error (%.2g)' % (best + 1, gain, min_gain, noise))
    short = [w for w, ok in (('--min-gain %g' % min_gain, gain > min_gain),
                             ('twice the standard error (%.2g)' % noise, gain > noise)) if not ok]
    return None, stats, ('the lowest mean, trial %d\'s, beats the baseline by %.4g, not by more than %s: '
                         'the bags cannot tell it from the baseline, which is kept'
                         % (best + 1, gain, ' or '.join(short)))


def confirm(args, setup, study, client, say=print):
    """Runs the --confirm-top lowest trials and the baseline with --confirm-seeds more seeds. Returns
    the chosen trial's number, {number: (mean, standard error)}, the verdict and the per-seed values
    {number: [value per seed]}."""
    from optuna.trial import TrialState
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    baseline = complete[0]
    ranked = sorted((t for t in complete[1:]), key=lambda t: (t.value, t.number))[:args.confirm_top]
    seeds = [args.seed + k for k in range(1, args.confirm_seeds + 1)]
    values = {t.number: [t.value] for t in [baseline] + ranked}
    if seeds:
        say('pf_tune: confirming the %d lowest trials and the baseline with %d more seeds each'
            % (len(ranked), len(seeds)))
        nb = len(setup['bags'])
        trials = [baseline] + ranked
        jobs = [j for t in trials for sd in seeds for j in jobs_for(setup, args, t.params, seed=sd)]
        results = run_jobs(client, jobs, say)
        for i, t in enumerate(trials):
            for k in range(len(seeds)):
                rs = results[(i * len(seeds) + k) * nb:(i * len(seeds) + k + 1) * nb]
                values[t.number].append(float(np.mean([r['score'] for r in rs])))
    chosen, stats, verdict = choose(values[baseline.number], {t.number: values[t.number] for t in ranked},
                                    args.min_gain)
    stats[baseline.number] = stats.pop('baseline')
    return (chosen if chosen is not None else baseline.number), stats, verdict, values
