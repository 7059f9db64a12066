"""pf_free_port (scripts/workspace.bash), the port every script's private ROS
master takes: below the kernel's ephemeral range, where no node's XML-RPC
server and no rostest master (which bind port 0) can take it first, and not
one a process listens on.

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
"""

import os
import resource
import socket
import subprocess
import unittest

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))


def free_ports(n):
    """n ports from pf_free_port, each from a shell of its own as the scripts call it."""
    script = 'source scripts/workspace.bash; for i in $(seq %d); do pf_free_port; done' % n
    out = subprocess.run(['bash', '-c', script], cwd=REPO, check=True, capture_output=True,
                         text=True).stdout
    return [int(p) for p in out.split()]


def ephemeral_low():
    with open('/proc/sys/net/ipv4/ip_local_port_range') as f:
        return int(f.read().split()[0])


class FreePortTest(unittest.TestCase):
    def test_ports_are_below_the_ephemeral_range(self):
        low = ephemeral_low()
        if low <= 21000:
            self.skipTest('no room below the ephemeral range (it starts at %d)' % low)
        ports = free_ports(30)
        self.assertEqual(30, len(ports))
        for port in ports:
            self.assertGreaterEqual(port, 20000)
            self.assertLess(port, low, 'port %d is in the ephemeral range (from %d)' % (port, low))

    def test_a_port_in_use_is_never_given(self):
        # Hold most of the candidates: what is left must be what it gives.
        low = ephemeral_low()
        if low <= 21000:
            self.skipTest('no room below the ephemeral range (it starts at %d)' % low)
        # A socket each: room for them under the limit of open files.
        soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        want = (low - 20000) + 100
        if hard != resource.RLIM_INFINITY and hard < want:
            self.skipTest('the limit of open files (%d) is below the %d sockets it needs' % (hard, want))
        if soft != resource.RLIM_INFINITY and soft < want:
            resource.setrlimit(resource.RLIMIT_NOFILE, (want, hard))
        held = []
        try:
            for port in range(20000, 20000 + (low - 20000) * 3 // 4):
                s = socket.socket()
                try:
                    s.bind(('localhost', port))
                except OSError:
                    s.close()
                    continue
                held.append(s)
            taken = {s.getsockname()[1] for s in held}
            self.assertGreater(len(taken), (low - 20000) // 2, 'could not hold the ports')
            for port in free_ports(10):
                self.assertNotIn(port, taken)
        finally:
            for s in held:
                s.close()


if __name__ == '__main__':
    unittest.main()
