"""pf_free_port (scripts/workspace.bash), the port every script's private ROS
master takes: below the kernel's ephemeral range, where no node's XML-RPC
server and no rostest master (which bind port 0) can take it first, and not
one a process holds.

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
"""

import os
import socket
import subprocess
import unittest

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))


def free_ports(n, env=None):
    """n ports from pf_free_port, as the scripts call it (with `env` added)."""
    script = 'source scripts/workspace.bash; for i in $(seq %d); do pf_free_port; done' % n
    out = subprocess.run(['bash', '-c', script], cwd=REPO, check=True, capture_output=True,
                         text=True, env=dict(os.environ, **(env or {}))).stdout
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
        # In a range of its own (PF_FREE_PORT_RANGE), below the one the scripts
        # draw from, so that holding ports here cannot take one a script just
        # drew for its master: nine in ten held, what is left must be what it gives.
        first, high = 19000, 19100
        held = []
        try:
            for port in range(first, high - 10):
                s = socket.socket()
                try:
                    s.bind(('localhost', port))
                except OSError:
                    s.close()
                    continue
                held.append(s)
            taken = {s.getsockname()[1] for s in held}
            self.assertGreater(len(taken), 80, 'could not hold the ports')
            ports = free_ports(10, {'PF_FREE_PORT_RANGE': '%d %d' % (first, high)})
            self.assertEqual(10, len(ports))
            for port in ports:
                self.assertTrue(first <= port < high, port)
                self.assertNotIn(port, taken)
        finally:
            for s in held:
                s.close()

if __name__ == '__main__':
    unittest.main()
