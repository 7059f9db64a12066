"""pose_checker's evaluation of a track or initialpose watch (pose_checker.py's docstring): the
window the errors count in, the bounds checked on the compared poses, the verdict with its summary,
the timeline of the error and the samples' CSV. A mixin of PoseChecker (pose_checker_track.py),
whose watch gathered what it reads."""
import csv
import math

import rospy

from pose_checker_node import node_alive
from pose_checker_poses import pos_err, pose2_of_pose, yaw_err_deg


def fmt(x, unit='', prec=3):
    if x is None:
        return '-'
    return ('%.' + str(prec) + 'f%s') % (x, unit)


class TrackEvaluation:
    """PoseChecker's evaluation, run once its watch has ended."""

    def _window_start(self):
        start = self.start_after
        if self.mode == 'initialpose':
            start = self.ip_time + self.start_after
            if self.ip_sent is not None:
                start = self.rel(self.ip_sent[0]) + self.start_after
        if self.start_after_map is not None and self.map_t is not None:
            start = max(start, self.map_t + self.start_after_map)
        return start

    def evaluate(self, end_reason):
        failures = []
        hard = []  # failures that expect_failure never excuses (crash, no output, too little data)
        info = []
        samples = sorted(self.samples, key=lambda s: s.t)
        start = self._window_start()
        if self.start_after_map is not None and self.map_t is None:
            failures.append('no /map received (start_after_map is set)')
        if self.map_not_before is not None and self.map_t is not None and self.map_t < self.map_not_before:
            failures.append('test setup: /map arrived at t=%.1f s, before t=%.1f s (map_not_before): the map was '
                            'not late, raise map_delay' % (self.map_t, self.map_not_before))
        win = [s for s in samples if s.t >= start]
        have = [s for s in win if s.est is not None]
        missing = [s for s in win if s.est is None]
        fallbacks = [s for s in win if s.fallback and s.est is not None]

        if self.mode == 'initialpose':
            if self.ip_sent is None:
                failures.append('the /initialpose was never published (ground truth ended before t=%.1f s)' % self.ip_time)
            elif not self.ip_done:
                failures.append('no pf_pose after the /initialpose before the end')
            failures.extend(self.ip_notes)

        if len(have) < self.min_samples:
            hard.append('only %d compared poses after t=%.1f s (min_samples %d)' % (len(have), start, self.min_samples))
        if missing:
            s = missing[0]
            failures.append('t=%.1f s: no estimate (%s -> %s unavailable on tf); %d ground-truth poses without an estimate'
                            % (s.t, self.global_frame, self.base_frame, len(missing)))

        def first_over(seq, attr, bound, unit, what):
            bad = [s for s in seq if getattr(s, attr) > bound]
            if bad:
                worst = max(bad, key=lambda s: getattr(s, attr))
                failures.append('t=%.1f s: %s %.3f%s > %.3f%s (%d of %d poses over; worst %.3f%s at t=%.1f s)' % (
                    bad[0].t, what, getattr(bad[0], attr), unit, bound, unit, len(bad), len(seq),
                    getattr(worst, attr), unit, worst.t))

        if self.max_error is not None:
            first_over(have, 'err', self.max_error, ' m', 'error')
        if self.max_yaw_error is not None:
            first_over(have, 'yaw_err', self.max_yaw_error, ' deg', 'yaw error')

        errs = [s.err for s in have]
        yerrs = [s.yaw_err for s in have]
        rmse = math.sqrt(sum(e * e for e in errs) / len(errs)) if errs else None
        yrmse = math.sqrt(sum(e * e for e in yerrs) / len(yerrs)) if yerrs else None
        median = sorted(errs)[len(errs) // 2] if errs else None
        worst = max(have, key=lambda s: s.err) if have else None
        if self.rmse_below is not None and rmse is not None and rmse > self.rmse_below:
            failures.append('position RMSE %.3f m > %.3f m (t >= %.1f s, n=%d)' % (rmse, self.rmse_below, start, len(errs)))
        if self.yaw_rmse_below is not None and yrmse is not None and yrmse > self.yaw_rmse_below:
            failures.append('yaw RMSE %.2f deg > %.2f deg (t >= %.1f s, n=%d)' % (yrmse, self.yaw_rmse_below, start, len(yerrs)))

        def settle(seq, t_from, within, bound, what):
            """Checks that the error is below `bound` from some time <= t_from + within to the end."""
            seq = [s for s in seq if s.t >= t_from]
            if not seq:
                failures.append('%s: no ground truth after t=%.1f s' % (what, t_from))
                return
            last_bad = None
            for s in seq:
                if s.err >= bound:
                    last_bad = s
            deadline = t_from + within
            if seq[-1].t < deadline:
                failures.append('%s: ground truth ended at t=%.1f s, before the deadline t=%.1f s' % (what, seq[-1].t, deadline))
                return
            if last_bad is None:
                info.append('%s: below %.2f m from t=%.1f s on' % (what, bound, seq[0].t))
                return
            after = [s for s in seq if s.t > last_bad.t]
            settled_at = after[0].t if after else None
            if settled_at is not None and settled_at <= deadline:
                info.append('%s: below %.2f m from t=%.1f s on (deadline t=%.1f s)' % (what, bound, settled_at, deadline))
                return
            err = 'no estimate' if last_bad.est is None else 'error %.3f m > %.3f m' % (last_bad.err, bound)
            over = [s for s in seq if s.t >= deadline and s.err >= bound]
            failures.append('t=%.1f s: %s (%s: must stay below %.2f m from t=%.1f s on; %d of %d poses after the deadline over)' % (
                last_bad.t, err, what, bound, deadline, len(over), len([s for s in seq if s.t >= deadline])))

        if self.converge_within is not None:
            settle(samples, 0.0, self.converge_within, self.converge_error if self.converge_error is not None else 0.3,
                   'convergence')
        if self.event_auto:
            # The event is the first jump of the ground truth by more than jump_threshold.
            for a, b in zip(samples, samples[1:]):
                if pos_err(a.truth, b.truth) > self.jump_threshold:
                    self.event_time = b.t
                    info.append('ground truth jumps %.2f m at t=%.2f s (event_time auto)' % (pos_err(a.truth, b.truth), b.t))
                    break
            else:
                failures.append('event_time auto: the ground truth never jumps by more than %.2f m' % self.jump_threshold)
        if self.event_time is not None and self.recover_within is not None:
            settle(samples, self.event_time, self.recover_within,
                   self.recover_error if self.recover_error is not None else 0.3, 'recovery after t=%.1f s' % self.event_time)

        self._check_confidently_wrong(have, start, failures, info)

        with self.lock:
            n_pf = len([1 for r, _ in self.pf_poses if self.t0 is not None and self.rel(r) >= start])
            n_pf_all = len(self.pf_poses)
        if n_pf < self.min_pf_pose:
            hard.append('only %d pf_pose messages after t=%.1f s (min_pf_pose %d; %d in total)' % (
                n_pf, start, self.min_pf_pose, n_pf_all))

        if self.saved_pose_ns:
            self._check_saved_pose(failures, info)

        if self.check_alive:
            ok, why = node_alive(self.check_alive)
            if not ok:
                hard.append('%s is not alive at the end: %s' % (self.check_alive, why))
            else:
                info.append('%s alive at the end (%s)' % (self.check_alive, why))

        summary = ('n=%d (t >= %.1f s; %d fallback lookups, %d without estimate, %d before the window)  '
                   'position error RMSE %s  median %s  max %s%s  |  yaw RMSE %s  max %s  |  pf_pose msgs %d'
                   % (len(have), start, len(fallbacks), len(missing), len(samples) - len(win),
                      fmt(rmse, ' m'), fmt(median, ' m'), fmt(worst.err if worst else None, ' m'),
                      (' (t=%.1f s)' % worst.t) if worst else '',
                      fmt(yrmse, ' deg', 2), fmt(max(yerrs) if yerrs else None, ' deg', 2), n_pf_all))
        if self.map_stamp is not None and self.map_stamp.is_zero():
            info.append('/map arrived before the clock started')
        elif self.map_t is not None:
            info.append('/map arrived at t=%.1f s' % self.map_t)
        info.append('watch ended: %s' % end_reason)
        if self.mode == 'initialpose':
            info = self.ip_info + info
        self._print_timeline(samples, start)
        self._write_samples(samples)

        text = 'pose_checker [%s]: %s\n  %s' % (self.mode, summary, '\n  '.join(info))
        return self._verdict(failures, hard, text)

    def _check_confidently_wrong(self, have, start, failures, info):
        """pf_status verdicts of "localized" while the estimate was more than wrong_error off."""
        with self.lock:
            states = [(self.rel(r), st) for r, st in self.states if self.t0 is not None and not r.is_zero()]
        times = [s.t for s in have]
        wrong = []
        for t, state in states:
            if t < start or state != 'localized' or not times:
                continue
            k = min(range(len(times)), key=lambda i: abs(times[i] - t))
            if abs(times[k] - t) <= 0.5 and have[k].err > self.wrong_error:
                wrong.append((t, have[k].err))
        n = len([1 for t, _ in states if t >= start])
        info.append('confidently wrong: %d of %d pf_status messages said "localized" while more than %.1f m off%s'
                    % (len(wrong), n, self.wrong_error,
                       (' (first at t=%.1f s, %.2f m)' % wrong[0]) if wrong else ''))
        if self.max_confidently_wrong is not None and len(wrong) > self.max_confidently_wrong:
            failures.append('%d pf_status messages said "localized" while more than %.1f m off (at most %d allowed); '
                            'first at t=%.1f s, %.2f m off' % (len(wrong), self.wrong_error,
                                                             self.max_confidently_wrong, wrong[0][0], wrong[0][1]))

    def _check_saved_pose(self, failures, info):
        ns = self.saved_pose_ns.rstrip('/')
        try:
            saved = tuple(float(rospy.get_param('%s/initial_pose_%s' % (ns, k))) for k in 'xya')
        except KeyError as e:
            failures.append('no saved pose on the parameter server: %s is not set' % e)
            return
        if self.last_gt is None:
            return
        truth = pose2_of_pose(self.last_gt.pose)
        e = pos_err(saved, truth)
        info.append('saved pose %s/initial_pose_*: x=%.3f y=%.3f a=%.3f, %.3f m / %.1f deg from the last '
                    'ground truth' % (ns, saved[0], saved[1], saved[2], e, yaw_err_deg(saved, truth)))
        if not e <= self.saved_pose_error:
            failures.append('saved pose %s/initial_pose_* is %.2f m > %.2f m from the last ground truth'
                            % (ns, e, self.saved_pose_error))

    def _verdict(self, failures, hard, text):
        if hard:
            msg = 'FAILED: %s\n%s' % ('\n  '.join(hard + failures), text)
            print(msg)
            return False, msg
        if self.expect_failure:
            if failures:
                msg = 'EXPECTED FAILURE (expect_failure is set): %s\n%s' % ('; '.join(failures), text)
                print(msg)
                return True, msg
            msg = 'UNEXPECTED PASS: remove expect_failure from the test, the checks now pass.\n%s' % text
            print(msg)
            return False, msg
        if failures:
            msg = 'FAILED: %s\n%s' % ('\n  '.join(failures), text)
            print(msg)
            return False, msg
        msg = 'PASSED\n%s' % text
        print(msg)
        return True, msg

    def _print_timeline(self, samples, start):
        if not samples:
            return
        lines = ['pose_checker timeline (5 s bins of sim time; position error max/mean, yaw error max):']
        b = 0
        t_end = samples[-1].t
        while b * 5.0 <= t_end:
            lo, hi = b * 5.0, (b + 1) * 5.0
            bin_s = [s for s in samples if lo <= s.t < hi]
            est = [s for s in bin_s if s.est is not None]
            if bin_s:
                if est:
                    lines.append('  t=%5.1f..%5.1f s%s  max %.3f m  mean %.3f m  yaw max %5.1f deg  n=%d%s' % (
                        lo, hi, '*' if hi <= start else ' ', max(s.err for s in est),
                        sum(s.err for s in est) / len(est), max(s.yaw_err for s in est), len(est),
                        '' if len(est) == len(bin_s) else '  (%d without estimate)' % (len(bin_s) - len(est))))
                else:
                    lines.append('  t=%5.1f..%5.1f s%s  no estimate (n=%d)' % (lo, hi, '*' if hi <= start else ' ', len(bin_s)))
            b += 1
        lines.append('  (* = before the evaluation window starts at t=%.1f s)' % start)
        print('\n'.join(lines))

    def _write_samples(self, samples):
        if not self.samples_file:
            return
        try:
            with open(self.samples_file, 'w', newline='') as f:
                w = csv.writer(f)
                w.writerow(['t', 'stamp', 'true_x', 'true_y', 'true_yaw', 'est_x', 'est_y', 'est_yaw', 'error_m',
                            'yaw_error_deg', 'fallback'])
                for s in samples:
                    e = s.est or (float('nan'),) * 3
                    w.writerow(['%.3f' % s.t, '%.6f' % s.stamp.to_sec(), s.truth[0], s.truth[1], s.truth[2],
                                e[0], e[1], e[2], s.err, s.yaw_err, int(s.fallback)])
        except OSError as e:
            rospy.logwarn('pose_checker: cannot write %s: %s', self.samples_file, e)
