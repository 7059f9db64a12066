#!/usr/bin/python3
"""rostest checker: pf_node refuses invalid parameters, naming them.

For each case below, starts the pf_node binary under this test's master with
the defaults of config/pf.yaml plus the bad values as private parameters
(`_name:=value`, each case under its own node name) and asserts that it exits
with status 1 within `timeout` s and that its output names the parameter and
the range it must lie in. A last run with the defaults only must still be
running after a few seconds: that shows the refusals come from the bad values.
"""
import os
import re
import subprocess
import sys
import time
import unittest

import roslib.packages
import rospy
import rostest
import yaml

PKG = 'pf_localization'
NAME = 'bad_params_checker'

# (what, {parameter: value}, texts the message must contain)
CASES = [
    ('negative particle count', {'max_particles': -5}, ['max_particles = -5', 'must be >= 1 (particles)']),
    ('min_particles above max_particles', {'min_particles': 1000, 'max_particles': 100},
     ['max_particles', '>= min_particles (1000)']),
    ('zero min_particles', {'min_particles': 0}, ['min_particles', '>= 1']),
    ('sigma_hit of 0', {'laser_sigma_hit': 0.0}, ['laser_sigma_hit', '> 0']),
    ('negative sigma_hit', {'laser_sigma_hit': -0.2}, ['laser_sigma_hit', '> 0']),
    ('negative odometry alpha', {'odom_alpha3': -0.1}, ['odom_alpha3', '>= 0']),
    ('z weights summing to 0', {'laser_z_hit': 0.0, 'laser_z_rand': 0.0},
     ['laser_z_hit + laser_z_rand', '> 0']),
    ('negative z weight', {'laser_z_rand': -0.5}, ['laser_z_rand', '>= 0']),
    ('unknown odometry model', {'odom_model_type': 'tank'},
     ['odom_model_type', 'diff, diff-corrected, omni or omni-corrected']),
    ('beam model rate of 0', {'laser_model_type': 'beam', 'laser_lambda_short': 0.0},
     ['laser_lambda_short', '> 0 (1/m)']),
    ('a word for a number', {'laser_sigma_hit': 'wide'}, ['laser_sigma_hit', 'expected a number']),
]


def pf_node_binary():
    found = roslib.packages.find_node(PKG, 'pf_node')
    if not found:
        raise RuntimeError('pf_node binary not found with roslib.packages.find_node')
    return found[0]


def yaml_arg(value):
    """A command-line value that ros::init parses back to the same YAML type."""
    if isinstance(value, float):
        return repr(value)
    return str(value)


class BadParamsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.binary = pf_node_binary()
        path = os.path.join(roslib.packages.get_pkg_dir(PKG), 'config', 'pf.yaml')
        with open(path) as f:
            cls.defaults = yaml.safe_load(f)
        cls.timeout = float(rospy.get_param('~timeout', 20.0))

    def start(self, name, params):
        # The defaults go on the parameter server, as the launch file puts them;
        # the case's values follow on the command line and replace them.
        for key, value in self.defaults.items():
            rospy.set_param('/%s/%s' % (name, key), value)
        args = [self.binary, '__name:=%s' % name]
        args += ['_%s:=%s' % (k, yaml_arg(v)) for k, v in params.items()]
        return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)

    def test_invalid_parameters_are_refused_by_name(self):
        report = []
        for i, (what, params, texts) in enumerate(CASES):
            proc = self.start('pf_bad_params_%d' % i, params)
            try:
                out, _ = proc.communicate(timeout=self.timeout)
            except subprocess.TimeoutExpired:
                proc.kill()
                out, _ = proc.communicate()
                self.fail('%s %s: pf_node still running after %.0f s; output:\n%s'
                          % (what, params, self.timeout, out))
            out = re.sub(r'\x1b\[[0-9;]*m', '', out)  # rosconsole's colours
            refusal = [line for line in out.splitlines() if 'refusing to start' in line]
            report.append('%-36s exit %d: %s' % (what, proc.returncode, refusal[0].strip() if refusal else out))
            self.assertEqual(proc.returncode, 1, '%s %s: exit status %d, output:\n%s'
                             % (what, params, proc.returncode, out))
            self.assertTrue(refusal, '%s: no "refusing to start" line in:\n%s' % (what, out))
            for text in texts:
                self.assertIn(text, refusal[0], '%s: the message does not contain %r' % (what, text))
        print('bad_params_checker:\n  ' + '\n  '.join(report))
        sys.stdout.flush()

    def test_defaults_start(self):
        proc = self.start('pf_good_params', {})
        time.sleep(3.0)
        alive = proc.poll() is None
        proc.terminate()
        out, _ = proc.communicate(timeout=self.timeout)
        self.assertTrue(alive, 'pf_node with config/pf.yaml exited (status %s):\n%s' % (proc.returncode, out))


if __name__ == '__main__':
    rospy.init_node(NAME)
    rostest.rosrun(PKG, NAME, BadParamsTest, sys.argv)
