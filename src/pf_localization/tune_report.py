"""pf_tune's outputs in --out: best.yaml, the baseline's and the chosen trial's runs kept, the study's
plots and report.md."""
import os
import shutil
import textwrap

from pf_localization.tune_objective import FAIL_SCORE
from pf_localization.tune_space import baseline_point, format_value, write_params_yaml
from pf_localization.tune_study import confirm
from pf_localization.tune_tasks import jobs_for, run_jobs


def write_outputs(args, setup, study, client, say=print):
    from optuna.trial import TrialState
    out = os.path.abspath(args.out)
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    baseline = complete[0]
    chosen, stats, verdict, seed_values = confirm(args, setup, study, client, say)
    best = study.trials[chosen]
    study.set_user_attr('chosen_trial', chosen)
    nseeds = args.confirm_seeds + 1
    header = ''.join('# %s\n' % ln for ln in textwrap.wrap(
        'pf_tune: trial %d of %d (%s loss %.6g, mean over %d seed(s) %.6g; baseline %.6g) of study "%s", '
        'on %s: %s. Tuned: %s.' % (
            best.number + 1, len(complete), setup['objective'], best.value, nseeds, stats[chosen][0],
            stats[baseline.number][0],
            args.study_name, ', '.join(os.path.basename(b) for b in setup['bags']), verdict,
            ', '.join(sorted(best.params))), 98))
    values = {k: (int(v) if setup['space'][k]['type'] == 'int' else float(v)) for k, v in best.params.items()}
    write_params_yaml(setup['base_text'], values, os.path.join(out, 'best.yaml'), header)

    # The baseline's and the best trial's runs once more, keeping their files (same seed: same runs).
    runs = os.path.join(out, 'runs')
    shutil.rmtree(runs, ignore_errors=True)
    base_pt = baseline_point(setup['space'], setup['base'])
    kept = run_jobs(client, jobs_for(setup, args, base_pt, os.path.join(runs, 'baseline')) +
                    jobs_for(setup, args, values, os.path.join(runs, 'best')), say)
    nb = len(setup['bags'])
    before, after = kept[:nb], kept[nb:]
    pngs = save_study_plots(study, out, say)
    lines = report_lines(args, setup, study, out, dict(
        baseline=baseline, best=best, values=values, chosen=chosen, stats=stats, verdict=verdict,
        seed_values=seed_values, before=before, after=after, pngs=pngs))
    with open(os.path.join(out, 'report.md'), 'w') as f:
        f.write('\n'.join(lines) + '\n')
    return best, baseline, verdict


def save_study_plots(study, out, say=print):
    """history.png and importances.png in out (Optuna's matplotlib plots); returns the
    (title, file) of those written."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    import optuna.visualization.matplotlib as ovm
    import warnings
    pngs = []
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        plots = [(ovm.plot_optimization_history, 'history.png', 'Optimisation history',
                  'no history plot'),
                 (ovm.plot_param_importances, 'importances.png', 'Parameter importances (fANOVA)',
                  'no importance plot (needs at least two distinct completed trials and scikit-learn)')]
        for plot, name, title, failed in plots:
            try:
                ax = plot(study)
                ax.figure.set_size_inches(8, 4.5)
                ax.figure.tight_layout()
                ax.figure.savefig(os.path.join(out, name), dpi=100)
                plt.close(ax.figure)
                pngs.append((title, name))
            except Exception as e:
                say('pf_tune: warning: %s: %s' % (failed, e))
    return pngs


def report_lines(args, setup, study, out, found):
    """report.md's lines; found: what write_outputs found (the baseline, best and chosen trials, the
    chosen values, the confirmation's statistics and verdict, the kept runs, the plots)."""
    from optuna.trial import TrialState
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    baseline, best, values, chosen, stats = (found[k] for k in (
        'baseline', 'best', 'values', 'chosen', 'stats'))
    nseeds = args.confirm_seeds + 1

    def metric_cells(r):
        if not r.get('ok'):
            return ['failed: %s' % (r.get('error') or '?').replace('|', '/')[:80]]
        m = r.get('metrics', {})
        if setup['objective'] == 'reference':
            return ['%.4f' % r['score'], 'ATE %.3f m, %.1f %% off' % (m['ate_rmse_m'], 100 * m['off_share'])]
        return ['%.4f' % r['score'], 'fit %.3f, lost %.2f, uncertain %.2f, %d jumps'
                % (m['fit'], m['lost_share'], m['uncertain_share'], m['jumps'])]

    lines = ['# pf_tune report: study "%s"' % args.study_name, '',
             '- objective: **%s** (%s); lower is better; failure scores %g' % (
                 setup['objective'], setup['why'], FAIL_SCORE[setup['objective']]),
             '- bags: %s' % ', '.join('`%s`' % b for b in setup['bags']),
             '- sensors: %s' % ', '.join('`%s`' % t for t in (args.scan_topic or ['/scan']) +
                                         (args.cloud_topic or [])),
             '- trials: %d complete of %d; seed %d; storage `%s`' % (
                 len(complete), len(study.trials), args.seed,
                 args.storage or 'sqlite:///%s' % os.path.join(out, 'study.db')),
             '- baseline (trial %d, the --params-from values): **%.5f**; chosen: trial %d, **%.5f**' % (
                 baseline.number + 1, baseline.value, best.number + 1, best.value),
             '- choice: %s' % found['verdict'],
             '- parameters: `best.yaml` (load with `pf_bag_runner --params %s/best.yaml`)' % out, '',
             '## Parameters', '', '| parameter | range | baseline | best |', '|---|---|---|---|']
    for k, s in setup['space'].items():
        lines.append('| %s | %g .. %g%s | %s | %s |' % (k, s['low'], s['high'], ' (log)' if s['log'] else '',
                                                      format_value(setup['base'][k]), format_value(values[k])))
    lines += ['', '## Confirmation: the lowest trials again, with %d seed(s) each' % nseeds, '',
              'Seeds %s; a value is the mean over the bags, as in the study. See pf_tune --help, '
              '"Choosing the best".' % ', '.join(str(args.seed + k) for k in range(nseeds)), '',
              '| trial | value per seed | mean | standard error |', '|---|---|---|---|']
    for number, vals in found['seed_values'].items():
        m, se = stats[number]
        lines.append('| %d%s%s | %s | %.5f | %.5f |' % (
            number + 1, ' (baseline)' if number == baseline.number else '', ' **chosen**' if number == chosen else '',
            ', '.join('%.5f' % v for v in vals), m, se))
    lines += ['', '## Per bag: baseline vs. chosen', '', '| bag | baseline | | chosen | |', '|---|---|---|---|---|']
    for b, r0, r1 in zip(setup['bags'], found['before'], found['after']):
        c0, c1 = metric_cells(r0), metric_cells(r1)
        c0 += [''] * (2 - len(c0))
        c1 += [''] * (2 - len(c1))
        lines.append('| %s | %s | %s | %s | %s |' % (os.path.basename(b), c0[0], c0[1], c1[0], c1[1]))
    for title, png in found['pngs']:
        lines += ['', '## %s' % title, '', '![%s](%s)' % (title, png)]
    if found['pngs']:
        lines += ['', "(Optuna's plots number the trials from 0: trial N of this report is N - 1 there.)"]
    lines += ['', '## Trials', '', '| trial | value | state | failed bags |', '|---|---|---|---|']
    for t in study.trials:
        failed = [os.path.basename(r['bag']) for r in t.user_attrs.get('bags', []) if not r.get('ok')]
        lines.append('| %d | %s | %s | %s |' % (t.number + 1, '%.5f' % t.value if t.value is not None else '-',
                                               t.state.name, ', '.join(failed)))
    return lines
