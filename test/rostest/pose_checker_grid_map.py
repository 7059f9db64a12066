"""pose_checker's map for the bad_input mode: ray casting and free-space search in the received
nav_msgs/OccupancyGrid."""
import math

from pose_checker_poses import yaw_of


class GridMap:
    """Ray casting and free-space search in a nav_msgs/OccupancyGrid (numpy)."""

    def __init__(self, msg):
        import numpy as np
        self.np = np
        info = msg.info
        self.res = info.resolution
        self.w, self.h = info.width, info.height
        self.ox, self.oy = info.origin.position.x, info.origin.position.y
        self.oyaw = yaw_of(info.origin.orientation)
        g = np.array(msg.data, dtype=np.int16).reshape(self.h, self.w)
        self.occ = g >= 50
        self.free = (g >= 0) & (g < 50)

    def free_pose(self):
        """The free cell farthest from any occupied or unknown cell (4-neighbour erosion)."""
        np = self.np
        m = self.free.copy()
        last = m
        for _ in range(max(self.w, self.h)):
            e = m.copy()
            e[1:, :] &= m[:-1, :]
            e[:-1, :] &= m[1:, :]
            e[:, 1:] &= m[:, :-1]
            e[:, :-1] &= m[:, 1:]
            e[0, :] = e[-1, :] = False
            e[:, 0] = e[:, -1] = False
            if not e.any():
                break
            last, m = e, e
        ys, xs = np.nonzero(last)
        if len(xs) == 0:
            raise RuntimeError('the map has no free cell')
        i = len(xs) // 2
        return self.cell_to_world(xs[i] + 0.5, ys[i] + 0.5)

    def cell_to_world(self, cx, cy):
        c, s = math.cos(self.oyaw), math.sin(self.oyaw)
        lx, ly = cx * self.res, cy * self.res
        return (self.ox + c * lx - s * ly, self.oy + s * lx + c * ly)

    def cast(self, pose, angles, range_max):
        np = self.np
        step = self.res * 0.5
        d = np.arange(step, range_max, step)
        a = pose[2] + np.asarray(angles) - self.oyaw
        wx = pose[0] - self.ox
        wy = pose[1] - self.oy
        c, s = math.cos(-self.oyaw), math.sin(-self.oyaw)
        lx, ly = c * wx - s * wy, s * wx + c * wy
        px = (lx + np.outer(np.cos(a), d)) / self.res
        py = (ly + np.outer(np.sin(a), d)) / self.res
        ix, iy = np.floor(px).astype(int), np.floor(py).astype(int)
        inside = (ix >= 0) & (iy >= 0) & (ix < self.w) & (iy < self.h)
        hit = np.zeros_like(inside)
        hit[inside] = self.occ[iy[inside], ix[inside]]
        first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
        return [float(d[k]) if k >= 0 else float('inf') for k in first]
