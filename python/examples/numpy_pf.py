"""The ECE276A reports' particle-filter SLAM in vectorised NumPy, as a slamrig estimator.

The method of the ECE276A reports (Wang, Kansal, Zafari): particles move by the
synchronised odometry increment plus Gaussian noise; each particle's scan endpoints are
correlated with the binary occupancy map (log-odds > 0) over a small grid of cell shifts, the
best shift moves the particle; weights are multiplied by the softmax of the correlations; the
best particle's scan updates the log-odds map (hit +log 4, free -log 4 along the ray, clamped);
stratified resampling when N_eff < neff_fraction * N.

Not the reports': the measurement update runs only after the robot moved `min_update_distance`
or turned `min_update_angle` since the last one (between updates the particles are predicted
only), and every `beam_step`-th beam is used, which keeps a pure-NumPy filter fast enough to
run the office scenario. Every random number comes from `numpy.random.default_rng(seed)`, so a
run is repeatable bit for bit.
"""

import math

import numpy as np


class ReportsParticleFilter:
    def __init__(self, seed=1, particles=30, resolution=0.05, map_size_m=80.0, shift_cells=2,
                 beam_step=2, max_range=20.0, motion_noise_xy=0.05, motion_noise_yaw=0.05,
                 motion_noise_floor=0.002, temperature=1.0, neff_fraction=0.5,
                 min_update_distance=0.1, min_update_angle=0.1, hit=math.log(4.0),
                 miss=-math.log(4.0), log_odds_limit=20.0):
        self.rng = np.random.default_rng(seed)
        self.n = int(particles)
        self.res = float(resolution)
        self.cells = int(round(map_size_m / self.res))
        # The estimator's frame is base_link at the first scan: put it in the middle.
        self.origin = np.array([-0.5 * self.cells * self.res] * 2)
        self.log_odds = np.zeros((self.cells, self.cells), dtype=np.float32)
        shifts = np.arange(-int(shift_cells), int(shift_cells) + 1)
        sx, sy = np.meshgrid(shifts, shifts, indexing="ij")
        self.shifts = np.stack([sx.ravel(), sy.ravel()], axis=1)  # (S, 2) in cells
        self.beam_step = int(beam_step)
        self.max_range = float(max_range)
        self.noise = (float(motion_noise_xy), float(motion_noise_yaw), float(motion_noise_floor))
        self.temperature = float(temperature)
        self.neff_fraction = float(neff_fraction)
        self.min_distance = float(min_update_distance)
        self.min_angle = float(min_update_angle)
        self.hit, self.miss, self.limit = float(hit), float(miss), float(log_odds_limit)

        self.poses = np.zeros((self.n, 3))
        self.weights = np.full(self.n, 1.0 / self.n)
        self.moved = np.zeros(2)  # distance and turn since the last update
        self.first = True
        self.neff_sum = 0.0
        self.scans = 0
        self.updates = 0
        self.resamples = 0
        self.bounds = None  # observed cells, for map()

    # --- the estimator interface -------------------------------------------------------------
    def add_scan(self, synced):
        scan = synced.scan
        ranges = scan.ranges[:: self.beam_step].astype(np.float64)
        angles = scan.angle_min + scan.angle_increment * np.arange(0, len(scan.ranges),
                                                                   self.beam_step)
        hit = (ranges >= scan.range_min) & (ranges < min(scan.range_max, self.max_range))
        mount = scan.base_from_laser
        c, s = math.cos(mount.theta), math.sin(mount.theta)
        lx, ly = ranges[hit] * np.cos(angles[hit]), ranges[hit] * np.sin(angles[hit])
        points = np.stack([mount.x + c * lx - s * ly, mount.y + s * lx + c * ly], axis=1)
        laser = np.array([mount.x, mount.y])

        if self.first:
            self.first = False
            self._map_update(np.zeros(3), points, laser)
            return self._estimate(1.0)

        inc = synced.increment
        self._predict(np.array([inc.x, inc.y, inc.theta]))
        self.moved += (math.hypot(inc.x, inc.y), abs(inc.theta))
        neff = 1.0 / float(np.sum(self.weights ** 2))
        if (self.moved[0] >= self.min_distance or self.moved[1] >= self.min_angle) and len(points):
            self.moved[:] = 0.0
            self.updates += 1
            self._correlate(points)
            best = int(np.argmax(self.weights))
            self._map_update(self.poses[best], points, laser)
            neff = 1.0 / float(np.sum(self.weights ** 2))
            if neff < self.neff_fraction * self.n:
                self._resample()
        return self._estimate(neff)

    def map(self):
        if self.bounds is None:
            return None
        (x0, y0), (x1, y1) = self.bounds
        origin = (self.origin[0] + x0 * self.res, self.origin[1] + y0 * self.res)
        return (self.log_odds[y0:y1 + 1, x0:x1 + 1], origin, self.res)

    def statistics(self):
        return {"mean_neff": self.neff_sum / max(self.scans, 1), "updates": float(self.updates),
                "resamples": float(self.resamples)}

    def particles(self):
        return np.column_stack([self.poses, self.weights])

    # --- the filter --------------------------------------------------------------------------
    def _predict(self, inc):
        a_xy, a_yaw, floor = self.noise
        d = math.hypot(inc[0], inc[1])
        std = np.array([a_xy * d + floor, a_xy * d + floor, a_yaw * abs(inc[2]) + a_xy * d + floor])
        local = inc + self.rng.normal(size=(self.n, 3)) * std
        c, s = np.cos(self.poses[:, 2]), np.sin(self.poses[:, 2])
        self.poses[:, 0] += c * local[:, 0] - s * local[:, 1]
        self.poses[:, 1] += s * local[:, 0] + c * local[:, 1]
        self.poses[:, 2] = np.remainder(self.poses[:, 2] + local[:, 2] + np.pi, 2 * np.pi) - np.pi

    def _cells(self, xy):
        return np.floor((xy - self.origin) / self.res).astype(np.int64)

    def _correlate(self, points):
        # Endpoints of every particle in the map: (N, B, 2) cells, then every shift: (N, S, B).
        c, s = np.cos(self.poses[:, 2:3]), np.sin(self.poses[:, 2:3])
        wx = self.poses[:, 0:1] + c * points[:, 0] - s * points[:, 1]
        wy = self.poses[:, 1:2] + s * points[:, 0] + c * points[:, 1]
        cells = self._cells(np.stack([wx, wy], axis=2))
        ix = cells[:, None, :, 0] + self.shifts[None, :, None, 0]
        iy = cells[:, None, :, 1] + self.shifts[None, :, None, 1]
        inside = (ix >= 0) & (iy >= 0) & (ix < self.cells) & (iy < self.cells)
        occupied = self.log_odds > 0.0
        corr = np.where(inside, occupied[np.clip(iy, 0, self.cells - 1),
                                         np.clip(ix, 0, self.cells - 1)], False).sum(axis=2)
        best_shift = np.argmax(corr, axis=1)
        self.poses[:, :2] += self.shifts[best_shift] * self.res
        score = corr[np.arange(self.n), best_shift] / self.temperature
        # Softmax update of the weights, in logs so that hundreds of hits do not overflow.
        log_w = np.log(self.weights + 1e-300) + score
        log_w -= np.max(log_w)
        w = np.exp(log_w)
        self.weights = w / np.sum(w)

    def _resample(self):
        # Stratified: one uniform draw in each of N equal strata of the cumulative weights.
        u = (np.arange(self.n) + self.rng.random(self.n)) / self.n
        index = np.minimum(np.searchsorted(np.cumsum(self.weights), u), self.n - 1)
        self.poses = self.poses[index]
        self.weights = np.full(self.n, 1.0 / self.n)
        self.resamples += 1

    def _map_update(self, pose, points, laser):
        c, s = math.cos(pose[2]), math.sin(pose[2])
        rot = np.array([[c, -s], [s, c]])
        ends = points @ rot.T + pose[:2]
        start = rot @ laser + pose[:2]
        # Free cells: samples every half cell along each ray, short of its end cell.
        lengths = np.linalg.norm(ends - start, axis=1)
        steps = max(int(np.max(lengths, initial=0.0) / (0.5 * self.res)), 1)
        t = np.linspace(0.0, 1.0, steps, endpoint=False)
        samples = start + (ends - start)[:, None, :] * t[None, :, None]
        keep = (t[None, :] * lengths[:, None]) < (lengths[:, None] - self.res)
        free = self._cells(samples[keep])
        hits = self._cells(ends)
        n = self.cells
        free = free[(free >= 0).all(axis=1) & (free < n).all(axis=1)]
        hits = hits[(hits >= 0).all(axis=1) & (hits < n).all(axis=1)]
        free_index = np.unique(free[:, 1] * n + free[:, 0])
        hit_index = np.unique(hits[:, 1] * n + hits[:, 0])
        free_index = np.setdiff1d(free_index, hit_index, assume_unique=True)
        flat = self.log_odds.reshape(-1)
        flat[free_index] = np.maximum(flat[free_index] + self.miss, -self.limit)
        flat[hit_index] = np.minimum(flat[hit_index] + self.hit, self.limit)
        if len(hits):
            lo, hi = hits.min(axis=0), hits.max(axis=0)
            if self.bounds is not None:
                lo, hi = np.minimum(lo, self.bounds[0]), np.maximum(hi, self.bounds[1])
            self.bounds = (lo, hi)

    def _estimate(self, neff):
        self.scans += 1
        self.neff_sum += neff
        best = self.poses[int(np.argmax(self.weights))]
        w = self.weights
        mean = (float(w @ self.poses[:, 0]), float(w @ self.poses[:, 1]),
                math.atan2(float(w @ np.sin(self.poses[:, 2])), float(w @ np.cos(self.poses[:, 2]))))
        return {"pose": (float(best[0]), float(best[1]), float(best[2])), "mean_pose": mean,
                "trace": {"neff": neff}}
