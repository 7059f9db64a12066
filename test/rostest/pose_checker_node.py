"""pose_checker's node: its private parameters, and what it asks the ROS master about the node
under test (alive and answering, publishing a topic)."""
import http.client
import xmlrpc.client

import rospy
import rosgraph


def param(name, default=None):
    return rospy.get_param('~' + name, default)


def opt_float(name):
    v = rospy.get_param('~' + name, None)
    if v is None or v == '':
        return None
    return float(v)


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout):
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host):
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


def node_alive(node, timeout=3.0):
    """(alive, why): the node is registered and answers its XML-RPC API."""
    try:
        master = rosgraph.Master(rospy.get_name())
        uri = master.lookupNode(node)
    except Exception as e:  # noqa: BLE001 - any master error means "not alive"
        return False, 'not registered with the master (%s)' % e
    try:
        code, _, pid = xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout)).getPid(rospy.get_name())
        if code != 1:
            return False, 'getPid returned code %s' % code
        return True, 'pid %s' % pid
    except (OSError, http.client.HTTPException, xmlrpc.client.Error) as e:
        return False, 'does not answer at %s (%s)' % (uri, e)


def node_publishes(node, topic):
    try:
        state = rosgraph.Master(rospy.get_name()).getSystemState()
    except Exception:  # noqa: BLE001
        return False
    for t, nodes in state[0]:
        if t == topic and node in nodes:
            return True
    return False
