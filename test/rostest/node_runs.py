"""Nodes a restart checker starts and stops itself (map_changes_restart_checker,
floors_restart_checker): each one's output in DIR/NAME.log, stopped with SIGINT as
roslaunch stops it, and killed at the end if still running. A test class mixes
NodeRuns in beside unittest.TestCase and sets `dir`, `procs` (a list) and `wait` (s)."""
import os
import re
import signal
import subprocess

import roslib.packages

PKG = 'pf_localization'


def binary(name):
    found = roslib.packages.find_node(PKG, name)
    if not found:
        raise RuntimeError('%s not found with roslib.packages.find_node' % name)
    return found[0]


class NodeRuns:
    def start_proc(self, name, args):
        log = open(os.path.join(self.dir, name + '.log'), 'w')
        # rosconsole flushes each line only to a terminal unless told to.
        env = dict(os.environ, ROSCONSOLE_STDOUT_LINE_BUFFERED='1')
        proc = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, env=env)
        self.procs.append((proc, log.name))
        return proc

    def output(self, name):
        with open(os.path.join(self.dir, name + '.log')) as f:
            return re.sub(r'\x1b\[[0-9;]*m', '', f.read())

    def interrupt(self, name, proc):
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=self.wait)
        except subprocess.TimeoutExpired:
            proc.kill()
            self.fail('%s still running %.0f s after SIGINT' % (name, self.wait))
        self.assertEqual(0, proc.returncode, '%s exited %d:\n%s'
                         % (name, proc.returncode, self.output(name)))

    @classmethod
    def kill_all(cls):
        for proc, _ in cls.procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
