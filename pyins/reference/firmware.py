"""The firmware instance: mode, one step per sample.

Mirrors ``csrc/src/firmware.{hpp,cpp}`` function by function, in the same
order: the instance takes a checked configuration (``config.py``) and
resolves it; each sample is checked (finite, not saturated, in sequence),
then advances one tick through the mode machine: coarse alignment, fine
alignment, navigation with indexing. Configurations, samples and outputs use
the C structs' field names, so a record from either engine reads the same.
Sample-level faults (NaN/Inf, saturation, seq gaps, duplicates, lost
sequences, encoder jumps) follow docs/core.md, "Sample-level faults":
``step(..., seq)`` returns the same statuses (negative: rejected, positive:
a notice) and the record carries the same bits and counters.
"""
import math

import numpy as np

from pyins.units import ARCMIN_TO_RAD

from . import (abi, attitude, coarse_align, config, earth, fine_align, indexing, moving_align, nav_filter,
               strapdown)
from .angle import wrap_pi, wrap_two_pi
from .attitude import cross
from .config import finite3
from .firmware_nav import NavAtSea

SEQ_NEXT, SEQ_GAP, SEQ_REPEAT, SEQ_LOST = 0, 1, 2, 3   #: SeqKind
U32 = 0xFFFFFFFF
#: kValidHeadingSigma: a fine-alignment attitude is valid only once the
#: filter's own heading sigma is within 10'
VALID_HEADING_SIGMA = 10.0 * ARCMIN_TO_RAD
#: kValidNavHeadingSigma: the navigation filter started on the coarse
#: attitude, once three times its heading sigma is within 10'
VALID_NAV_HEADING_SIGMA = VALID_HEADING_SIGMA / 3.0
COUNTERS = ("n_nonfinite", "n_saturated", "n_seq_gaps", "n_seq_bridged", "n_seq_repeats",
            "n_seq_lost", "n_encoder_jumps")   #: SampleCounts, as named in pyins_output


def within(v, limit):
    """Every component finite and inside the limit, a NaN comparing false
    (mirrors within)."""
    return abs(v[0]) < limit and abs(v[1]) < limit and abs(v[2]) < limit


def count(counter, n=1):
    """counter + n, saturating at 2^32 - 1 (mirrors count)."""
    return U32 if n > U32 - counter else counter + n


class Firmware(NavAtSea):
    """NumPy mirror of ``pyins::firmware::Firmware``.

    ``Firmware(cfg)`` with a dict like :func:`config.config_default`; raises
    ValueError if :func:`config.config_check` refuses it. ``step`` returns
    ``(status, output dict)``; ``pyins.reference.Firmware`` (c_api.py) is
    the engine with ``pyins.native.Firmware``'s contract.
    """

    def __init__(self, cfg=None):
        full = config.config_default()
        if cfg:
            full.update(cfg)
        status = config.config_check(full)
        if status != abi.PYINS_OK:
            raise ValueError(f"configuration refused with status {status}")
        self.init(full)

    def init(self, raw):
        cfg = config.config_resolved(raw)
        # after a coarse alignment the static filter's attitude sigmas left 0
        # stay 0: start_fine fits them to the coarse result
        if cfg["coarse_ticks"] > 0 and cfg["fine_states"] != 12:
            cfg["fine_sigma0_att_rad"] = np.array([0.0 if raw["fine_sigma0_att_rad"][i] == 0.0 else
                                                   cfg["fine_sigma0_att_rad"][i] for i in range(3)])
        self.cfg = cfg
        self.dt = 1.0 / float(cfg["tick_hz"])
        self.mode = abi.PYINS_MODE_IDLE
        self.att_valid = cfg["coarse_ticks"] == 0
        self.kf_states = 0
        self.fine_tick = 0
        self.align_restarts = 0
        self.gap_pending = False
        self.faults = 0
        self.fine = None
        self.tick = 0
        self.table_angle = cfg["table_angle_rad"]
        self.encoder = wrap_two_pi(cfg["table_angle_rad"])
        self.enc_sin_half = math.sin(0.5 * self.encoder)
        self.enc_cos_half = math.cos(0.5 * self.encoder)
        self.seq = 0
        self.seq_valid = False
        self.last_dtheta = np.zeros(3)
        self.last_dv = np.zeros(3)
        self.counts = dict.fromkeys(COUNTERS, 0)
        self.lever_b = np.array(cfg["lever_b_m"], dtype=float)
        self.lever_pp = np.array(cfg["lever_p_m"], dtype=float)
        self.has_lever = 1 if (np.any(self.lever_b != 0.0) or np.any(self.lever_pp != 0.0)) else 0
        self.rate_count = 0
        self.rate_p = np.zeros(3)
        self.alpha_rate = 0.0
        self.prev_dtheta = np.zeros(3)
        self.prev_dalpha = 0.0
        self.lever_vel_n = np.zeros(3)
        self.lever_refine = 0
        # the rates the lever arms need: the IMU's (has_lever), the DVL's or the antenna's (mirrors init)
        dl = cfg["dvl_lever_b_m"]
        gl = cfg["gnss_lever_b_m"]
        self.rates_on = 1 if (self.has_lever or dl[0] != 0.0 or dl[1] != 0.0 or dl[2] != 0.0 or gl[0] != 0.0
                              or gl[1] != 0.0 or gl[2] != 0.0) else 0
        self.integrity_lost = 0
        self.init_nav()
        self.fine_vrw = 0.0
        wander = cfg["integrity_coarse_rad"]
        self.coarse_wander_max = 1.0 if wander >= 0.5 * np.pi else math.sin(wander)
        euler_b = np.array(cfg["euler_b_rad"], dtype=float)
        mat_np = attitude.euler_to_mat(euler_b) @ attitude.rot_z(self.encoder)
        lon = cfg["lon_rad"]
        if lon > np.pi or lon <= -np.pi:
            lon = wrap_pi(wrap_two_pi(lon))
        nav = strapdown.NavState(cfg["lat_rad"], lon, cfg["height_m"],
                                 np.array(cfg["vel_n_mps"], dtype=float),
                                 attitude.mat_to_quat(mat_np))
        self.sd = strapdown.make_strapdown(nav, cfg["vertical_mode"])
        if cfg["index_scheme"] == abi.PYINS_INDEX_CUSTOM:
            steps = [indexing.Step(int(s), int(k), float(a))
                     for s, k, a in list(cfg["index_steps"])[:cfg["index_n_steps"]]]
        else:
            steps = indexing.preset_steps(cfg["index_scheme"], cfg["index_stop_ticks"])
        self.index_prm = indexing.Params(
            steps=steps, rate=cfg["index_rate_rad_s"], accel=cfg["index_accel_rad_s2"],
            delta=cfg["index_delta"], max_flex=cfg["index_max_flex_rad"],
            tolerance=cfg["index_tolerance_rad"], jump=cfg["index_jump_rad"],
            timeout_ticks=cfg["index_timeout_ticks"], dt=self.dt, sums=cfg["index_sums"],
            isolate=1 if cfg["index_scheme"] == abi.PYINS_INDEX_HEADING_ISOLATION else 0)
        idle = indexing.Params(**{**self.index_prm.__dict__, "steps": []})
        self.idx = indexing.init(idle, self.table_angle)
        self.coarse = None
        if cfg["coarse_ticks"] > 0:
            sin_lat, cos_lat = np.sin(cfg["lat_rad"]), np.cos(cfg["lat_rad"])
            prm = coarse_align.Params(
                method=cfg["coarse_method"], lever=self.has_lever, ratio=cfg["coarse_ratio"], first_output=cfg["coarse_first_output_ticks"],
                output_every=cfg["coarse_output_every_ticks"], dt=self.dt, sin_lat=sin_lat,
                cos_lat=cos_lat, gravity=earth.normal_gravity(sin_lat, cfg["height_m"]),
                settle_from=cfg["coarse_ticks"] - cfg["coarse_ticks"] // 5,
                ref_gap_max=config.COARSE_REF_GAP_S * cfg["tick_hz"],
                # the noise of the static fine filters' R (coarse_align, "Noise")
                noise_every=(cfg["fine_meas_every_ticks"] if cfg["fine_ticks"] > 0 and cfg["fine_states"] != 12
                             and cfg["fine_noise"] == abi.PYINS_FINE_NOISE_MEASURED else 0))
            rm, rn = earth.principal_radii(sin_lat)
            prm.rm_h = rm + cfg["height_m"]
            prm.rn_h = rn + cfg["height_m"]
            self.coarse = coarse_align.init(prm)

    def start_navigation(self):
        self.mode = abi.PYINS_MODE_NAVIGATE
        self.idx = indexing.init(self.index_prm, self.table_angle)
        if self.cfg["nav_mode"] != abi.PYINS_NAV_UNDAMPED:
            self.start_nav_filter()

    def ship_quat(self):
        """q_nb = q_np q_pb, q_pb = [cos(alpha/2), 0, 0, -sin(alpha/2)] (mirrors ship_quat)."""
        return attitude.quat_mul_z(self.sd.nav.quat_np, self.enc_cos_half, -self.enc_sin_half)

    def bow_n(self, horizontal=False):
        """The bow's horizontal direction in n (E, N; unit): C_b^n's column 1;
        (0, 0) for a vertical bow; with ``horizontal`` also the length of the
        column's horizontal part, cos(pitch) (mirrors bow_n)."""
        w, x, y, z = self.ship_quat()
        c01 = 2.0 * (x * y - w * z)
        c11 = w * w - x * x + y * y - z * z
        h = math.sqrt(c01 * c01 + c11 * c11)
        be, bn = (c01 / h, c11 / h) if h > 0.0 else (0.0, 0.0)
        return (be, bn, h) if horizontal else (be, bn)

    def imu_yaw_sincos(self):
        """sin and cos of psi_p = psi_b + alpha, no angle taken (mirrors
        Firmware::imu_yaw_sincos): the yaw's cosine and sine are the bow's
        north and minus its east component."""
        be, bn = self.bow_n()
        cb, sb = 1.0, 0.0  # atan2(0, 0) = 0
        if be != 0.0 or bn != 0.0:
            cb = bn
            sb = -be
        sa, ca = self.encoder_sincos()
        return sb * ca + cb * sa, cb * ca - sb * sa

    def update_rates(self, dtheta_p, dalpha):
        """Rates at the end of the tick, second order (mirrors update_rates)."""
        if self.rate_count == 0:
            self.rate_p = dtheta_p / self.dt
            self.alpha_rate = dalpha / self.dt
        else:
            self.rate_p = (1.5 * dtheta_p - 0.5 * self.prev_dtheta) / self.dt
            self.alpha_rate = (1.5 * dalpha - 0.5 * self.prev_dalpha) / self.dt
        self.prev_dtheta = np.array(dtheta_p, dtype=float)
        self.prev_dalpha = dalpha
        if self.rate_count < 2:
            self.rate_count = self.rate_count + 1

    def encoder_sincos(self):
        """sin and cos of the encoder angle from its cached half-angle
        (mirrors encoder_sincos)."""
        return (2.0 * self.enc_sin_half * self.enc_cos_half,
                self.enc_cos_half * self.enc_cos_half - self.enc_sin_half * self.enc_sin_half)

    def b_in_p(self, lb):
        """Rz(alpha)^T l: a vector of the ship in p (mirrors b_in_p)."""
        sa, ca = self.encoder_sincos()
        return np.array([ca * lb[0] + sa * lb[1], -sa * lb[0] + ca * lb[1], lb[2]])

    def lever_b_in_p(self):
        """Rz(alpha)^T lever_b (mirrors lever_b_in_p)."""
        return self.b_in_p(self.lever_b)

    def lever_p(self):
        """r^p = Rz(alpha)^T lever_b + lever_p (mirrors Firmware::lever_p)."""
        return self.lever_b_in_p() + self.lever_pp

    def gnss_lever_vel_p(self):
        """(w_ip^p - alpha' z) x Rz^T gnss_lever_b (mirrors gnss_lever_vel_p)."""
        w_b = self.rate_p - np.array([0.0, 0.0, self.alpha_rate])
        return cross(w_b, self.b_in_p(self.cfg["gnss_lever_b_m"]))

    def lever_vel_p(self):
        """u^p at the last tick's rates (mirrors lever_vel_p)."""
        return self.lever_vel_for(self.rate_p, self.alpha_rate)

    def lever_vel_for(self, rate_p, alpha_rate):
        """u^p = (w_ip^p - alpha' z) x Rz^T lever_b + w_ip^p x lever_p (mirrors lever_vel_for)."""
        w_b = rate_p - np.array([0.0, 0.0, alpha_rate])
        return cross(w_b, self.lever_b_in_p()) + cross(rate_p, self.lever_pp)

    def lever_vel_e_n(self, mat_np):
        """C_p^n u^p - w_ie^n x C_p^n r^p (mirrors lever_vel_e_n)."""
        lat = self.sd.nav.lat
        w_ie_n = np.array([0.0, earth.OMEGA_IE * np.cos(lat), earth.OMEGA_IE * np.sin(lat)])
        return mat_np @ self.lever_vel_p() - cross(w_ie_n, mat_np @ self.lever_p())

    def place_imu(self, lat, lon, height, vel_n):
        """The navigation state on the accelerometers of a reference point (mirrors place_imu)."""
        mat_np = attitude.quat_to_mat(self.sd.nav.quat_np)
        d = mat_np @ self.lever_p()
        sin_lat, cos_lat = np.sin(lat), np.cos(lat)
        rm, rn = earth.principal_radii(sin_lat)
        nav = self.sd.nav
        nav.lat = lat + d[1] / (rm + height)
        nav.lon = wrap_pi(lon + d[0] / ((rn + height) * cos_lat))
        nav.height = height + d[2]
        nav.vel_n = np.array(vel_n, dtype=float) + self.lever_vel_e_n(mat_np)
        if self.sd.vertical == strapdown.VERTICAL_HOLD:
            nav.vel_n[2] = 0.0
            self.sd.ref_height = nav.height

    def reference_point(self):
        """(lat, lon, height, vel_n) of the reference point (mirrors reference_point)."""
        nav = self.sd.nav
        mat_np = attitude.quat_to_mat(nav.quat_np)
        d = mat_np @ self.lever_p()
        sin_lat, cos_lat = np.sin(nav.lat), np.cos(nav.lat)
        rm, rn = earth.principal_radii(sin_lat)
        vel = nav.vel_n - self.lever_vel_e_n(mat_np)
        lat = nav.lat - d[1] / (rm + nav.height)
        lon = wrap_pi(nav.lon - d[0] / ((rn + nav.height) * cos_lat))
        return lat, lon, nav.height - d[2], vel

    def moving_fine(self, dtheta_p, dv_p):
        """One tick of the moving-base fine alignment (mirrors moving_fine)."""
        dv_sf_n = strapdown.update(self.sd, dtheta_p, dv_p, self.dt)
        z = (0.0, 0.0)
        if moving_align.measure(self.fine):
            lat, lon = self.sd.nav.lat, self.sd.nav.lon
            if self.has_lever:
                lat, lon, _, _ = self.reference_point()
            z = (wrap_pi(lon - self.sd.ref_lon) * self.fine.prm.rn_h * self.fine.prm.cos_lat,
                 (lat - self.cfg["lat_rad"]) * self.fine.prm.rm_h)
        updated = moving_align.step(self.fine, dv_sf_n, z)
        if not self.fine.healthy:
            self.faults = self.faults | abi.PYINS_FAULT_KF_NOT_PD
        if not self.fine.consistent:
            self.faults = self.faults | abi.PYINS_FAULT_ALIGN_INCONSISTENT
            self.integrity_lost = 1
        if updated:
            self.apply_fine_correction()
        self.fine_tick = self.fine_tick + 1
        if self.fine_tick == self.cfg["fine_ticks"]:
            self.end_fine()

    def index_reset(self):
        if self.idx.state == indexing.STATE_FAULT:
            self.idx = indexing.reset(self.idx, self.table_angle)

    def end_coarse(self):
        """Navigation starts from the coarse attitude, at rest, with its history;
        under way where the references carried the reference point, at the last
        one's velocity less its antenna's lever (mirrors end_coarse)."""
        nav = self.sd.nav
        nav = strapdown.NavState(nav.lat, nav.lon, nav.height, np.zeros(3),
                                 attitude.mat_to_quat(coarse_align.mat_n_p(self.coarse)))
        lat = self.cfg["lat_rad"]
        lon = self.sd.ref_lon
        co = self.coarse
        if co.prm.method == coarse_align.METHOD_FIT_VEL:
            since = co.tick if co.ref_tick < 0 else co.tick - co.ref_tick
            if co.ref_tick < 0 or co.ref_gap > co.prm.ref_gap_max or since > co.prm.ref_gap_max:
                self.faults = self.faults | abi.PYINS_FAULT_ALIGN_INCONSISTENT
                self.integrity_lost = 1
            lat = lat + co.dlat
            lon = wrap_pi(lon + co.dlon)
            nav.lat = lat
            nav.lon = lon
            self.sd.nav = nav   # point_vel_n reads the latitude
            lever_v = self.point_vel_n(attitude.quat_mul_z(nav.quat_np, self.enc_cos_half, -self.enc_sin_half),
                                       self.cfg["gnss_lever_b_m"])
            nav.vel_n = np.array([co.ref_vel[0] - lever_v[0], co.ref_vel[1] - lever_v[1], 0.0])
        self.sd = strapdown.make_strapdown(nav, self.sd.vertical)
        self.sd.hist = self.coarse.hist
        if self.has_lever:
            self.place_imu(lat, lon, self.cfg["height_m"], nav.vel_n)
        self.att_valid = True
        if self.cfg["fine_ticks"] > 0:
            self.start_fine()
        else:
            self.start_navigation()

    def start_fine(self):
        cfg = self.cfg
        sin_lat, cos_lat = np.sin(cfg["lat_rad"]), np.cos(cfg["lat_rad"])
        prm = fine_align.Params(
            sin_lat=sin_lat, cos_lat=cos_lat, gravity=earth.normal_gravity(sin_lat, cfg["height_m"]),
            dt=self.dt, meas_every=cfg["fine_meas_every_ticks"], gyro_arw=cfg["fine_gyro_arw"],
            accel_vrw=cfg["fine_accel_vrw"], sigma0_att=np.array(cfg["fine_sigma0_att_rad"], dtype=float),
            sigma0_gyro=cfg["fine_sigma0_gyro"], sigma0_accel=cfg["fine_sigma0_accel"],
            nis_window=max(cfg["integrity_nis_window"], 0), nis_max=cfg["integrity_nis_max"])
        if cfg["coarse_ticks"] > 0 and cfg["fine_states"] != 12:
            # R from the coarse phase's measured noise when larger (fine_noise MEASURED)
            measured = coarse_align.measured_vrw(self.coarse)
            if measured > prm.accel_vrw:
                prm.accel_vrw = measured
        self.fine_vrw = prm.accel_vrw
        if cfg["coarse_ticks"] > 0:
            fine_align.sigma0_after_coarse(prm, float(cfg["coarse_ticks"]) * self.dt, self.coarse.wander,
                                           config.DEFAULT_FINE_SIGMA_ATT)
        self.kf_states = cfg["fine_states"]
        self.fine_tick = 0
        if self.kf_states == 12:
            rm, rn = earth.principal_radii(sin_lat)
            mp = moving_align.Params(
                sin_lat=sin_lat, cos_lat=cos_lat, rm_h=rm + cfg["height_m"], rn_h=rn + cfg["height_m"],
                dt=self.dt, meas_every=cfg["fine_meas_every_ticks"], gyro_arw=cfg["fine_gyro_arw"],
                accel_vrw=cfg["fine_accel_vrw"], pos_sigma=cfg["fine_pos_sigma_m"],
                site_accel=cfg["fine_site_accel"],
                sigma0_att=np.array(cfg["fine_sigma0_att_rad"], dtype=float),
                sigma0_vel=cfg["fine_sigma0_vel_mps"], sigma0_gyro=cfg["fine_sigma0_gyro"],
                sigma0_accel=cfg["fine_sigma0_accel"], nis_window=prm.nis_window, nis_max=prm.nis_max)
            if cfg["coarse_ticks"] > 0:
                moving_align.sigma0_after_coarse(mp, float(cfg["coarse_ticks"]) * self.dt, self.coarse.wander,
                                                 prm.gravity)
        if self.has_lever:
            self.lever_vel_n = attitude.quat_to_mat(self.sd.nav.quat_np) @ self.lever_vel_p()
        self.fine = moving_align.init(mp) if self.kf_states == 12 else fine_align.init(self.kf_states, prm)
        self.mode = abi.PYINS_MODE_FINE_ALIGN

    def fine_phi(self):
        if self.mode != abi.PYINS_MODE_FINE_ALIGN:
            return np.zeros(3)
        return fine_align.phi(self.fine)

    def apply_fine_correction(self):
        """C_p^n = (I + phi x) C_p^n': rotate by phi^ in n, then phi^ = 0."""
        phi = self.fine_phi()
        q_phi = attitude.rotvec_to_quat(phi)
        self.sd.nav.quat_np = attitude.quat_normalize(attitude.quat_mul(q_phi, self.sd.nav.quat_np))
        if self.has_lever:
            # the lever velocity in n turns with the attitude (see firmware.cpp)
            self.lever_vel_n = attitude.quat_to_mat(q_phi) @ self.lever_vel_n
        if self.kf_states == 12:
            x = self.fine.x
            nav = self.sd.nav
            cos_lat = np.cos(nav.lat)
            nav.vel_n[0] = nav.vel_n[0] - x[moving_align.VEL]
            nav.vel_n[1] = nav.vel_n[1] - x[moving_align.VEL + 1]
            nav.lat = nav.lat - x[moving_align.POS + 1] / self.fine.prm.rm_h
            nav.lon = wrap_pi(nav.lon - x[moving_align.POS] / (self.fine.prm.rn_h * cos_lat))
            moving_align.reset_feedback(self.fine)
        else:
            fine_align.reset_phi(self.fine)

    def fine_heading_known(self):
        """The fine filter's heading sigma is within VALID_HEADING_SIGMA (mirrors fine_heading_known)."""
        return self.fine.p[2, 2] <= VALID_HEADING_SIGMA * VALID_HEADING_SIGMA

    def ref_aided(self):
        """A reference applied in navigation or met during the alignment (mirrors ref_aided)."""
        return any(self.ref_seen[i] != 0 or self.n_ref_skipped[i] != 0 for i in range(len(self.ref_seen)))

    def nav_heading_known(self):
        """The navigation filter's heading sigma is within VALID_NAV_HEADING_SIGMA (mirrors nav_heading_known)."""
        return self.nav.p[nav_filter.PHI + 2, nav_filter.PHI + 2] <= VALID_NAV_HEADING_SIGMA * VALID_NAV_HEADING_SIGMA

    def end_fine(self):
        if not self.fine_heading_known():
            self.att_valid = False
        self.apply_fine_correction()
        if self.has_lever and self.kf_states != 12:
            self.place_imu(self.cfg["lat_rad"], self.sd.ref_lon, self.cfg["height_m"], np.zeros(3))
        self.start_navigation()

    def hold_at_site(self):
        self.sd.nav.lat = self.cfg["lat_rad"]
        self.sd.nav.lon = self.sd.ref_lon
        self.sd.nav.height = self.cfg["height_m"]
        self.sd.nav.vel_n = np.zeros(3)
        self.sd.prev_dvel_n = np.zeros(3)
        if self.has_lever:
            self.place_imu(self.cfg["lat_rad"], self.sd.ref_lon, self.cfg["height_m"], np.zeros(3))

    def reject(self, fault_bit, counter):
        """A rejected sample: sticky bit, counter, alignment restart (mirrors reject)."""
        self.faults = self.faults | fault_bit
        self.counts[counter] = count(self.counts[counter])
        if self.mode in (abi.PYINS_MODE_COARSE_ALIGN, abi.PYINS_MODE_FINE_ALIGN):
            self.gap_pending = True
            self.faults = self.faults | abi.PYINS_FAULT_ALIGN_RESTARTED

    def seq_step(self, seq):
        """(kind, missing ticks) of a sample's seq (mirrors Firmware::seq_step)."""
        if self.cfg["seq_mode"] != abi.PYINS_SEQ_CHECK or not self.seq_valid:
            return SEQ_NEXT, 0
        d = (seq - self.seq) & U32
        g = self.cfg["seq_max_gap_ticks"]
        if d == 0 or d >= ((0 - g) & U32):
            return SEQ_REPEAT, 0
        if d > g + 1:
            return SEQ_LOST, (d - 1 if d < 0x80000000 else 0)
        if d > 1:
            return SEQ_GAP, d - 1
        return SEQ_NEXT, 0

    def usable(self, dtheta_p, dv_p, table_angle_rad):
        """Finite and within the saturation limits (mirrors Firmware::usable)."""
        return (within(dtheta_p, self.cfg["sat_gyro_rad"]) and within(dv_p, self.cfg["sat_accel_mps"])
                and math.isfinite(table_angle_rad))

    def reject_sample(self, dtheta_p, dv_p, table_angle_rad):
        """Step 1's slow path: non-finite, else saturated (mirrors reject_sample)."""
        if not (finite3(dtheta_p) and finite3(dv_p) and math.isfinite(table_angle_rad)):
            self.reject(abi.PYINS_FAULT_SAMPLE_NONFINITE, "n_nonfinite")
            return abi.PYINS_E_SAMPLE_NONFINITE, self.output()
        self.reject(abi.PYINS_FAULT_SAMPLE_SATURATED, "n_saturated")
        return abi.PYINS_E_SAMPLE_SATURATED, self.output()

    def ticks_for(self, dtheta_p, dv_p, table_angle_rad, seq=0):
        """Ticks stepping this sample would add (0: rejected or dropped); changes nothing."""
        if not self.usable(dtheta_p, dv_p, table_angle_rad):
            return 0
        kind, missing = self.seq_step(int(seq) & U32)
        return 0 if kind == SEQ_REPEAT else missing + 1

    def step(self, dtheta_p, dv_p, table_angle_rad, seq=0):
        """One sample; returns ``(status, output dict)`` (mirrors Firmware::step).

        ``seq`` is the IMU's sample counter (read with ``seq_mode`` = abi.PYINS_SEQ_CHECK).
        """
        # 1. Reject a non-finite sample, then a saturated one (one test, usable).
        if not self.usable(dtheta_p, dv_p, table_angle_rad):
            return self.reject_sample(dtheta_p, dv_p, table_angle_rad)
        # 2. The sequence: drop a duplicate; note a gap or a resynchronisation.
        seq = int(seq) & U32
        status = abi.PYINS_OK
        kind, missing = self.seq_step(seq)
        if kind == SEQ_REPEAT:
            self.faults = self.faults | abi.PYINS_FAULT_SEQ_REPEAT
            self.counts["n_seq_repeats"] = count(self.counts["n_seq_repeats"])
            return abi.PYINS_W_SEQ_REPEAT, self.output()
        resync = kind == SEQ_LOST
        if resync:
            self.faults = self.faults | abi.PYINS_FAULT_SEQ_LOST
            self.counts["n_seq_lost"] = count(self.counts["n_seq_lost"])
            status = abi.PYINS_W_SEQ_LOST
        elif kind == SEQ_GAP:
            self.faults = self.faults | abi.PYINS_FAULT_SEQ_GAP
            self.counts["n_seq_gaps"] = count(self.counts["n_seq_gaps"])
            status = abi.PYINS_W_SEQ_GAP
        # 3. The encoder reading, and its jump test.
        dtheta_p = np.array(dtheta_p, dtype=float)
        dv_p = np.array(dv_p, dtype=float)
        encoder = wrap_two_pi(table_angle_rad)
        if self.mode != abi.PYINS_MODE_IDLE and not resync and self.encoder_jumped(encoder, missing):
            self.faults = self.faults | abi.PYINS_FAULT_ENCODER_JUMP
            self.counts["n_encoder_jumps"] = count(self.counts["n_encoder_jumps"])
            if status == abi.PYINS_OK:
                status = abi.PYINS_W_ENCODER_JUMP
        # 4. Missing ticks: restart the alignment, skip them, or bridge them.
        if missing > 0 or resync:
            if self.mode in (abi.PYINS_MODE_COARSE_ALIGN, abi.PYINS_MODE_FINE_ALIGN):
                self.gap_pending = True
                self.faults = self.faults | abi.PYINS_FAULT_ALIGN_RESTARTED
                self.tick = self.tick + missing
            elif resync:
                self.tick = self.tick + missing
            else:
                self.bridge(missing, dtheta_p, dv_p, encoder)
                self.counts["n_seq_bridged"] = count(self.counts["n_seq_bridged"], missing)
        # 5. This sample's tick, and the memory for the next one.
        self.take(seq, dtheta_p, dv_p, encoder)
        return status, self.output()

    def encoder_jumped(self, encoder, missing):
        """More than index_jump_rad per tick over missing + 1 ticks (mirrors
        Firmware::encoder_jumped)."""
        return (encoder != self.encoder
                and abs(wrap_pi(encoder - self.encoder)) > self.cfg["index_jump_rad"] * float(missing + 1))

    def take(self, seq, dtheta_p, dv_p, encoder):
        """A sample's tick and the memory for the next one (mirrors Firmware::take)."""
        self.advance(dtheta_p, dv_p, encoder)
        self.last_dtheta = dtheta_p.copy()
        self.last_dv = dv_p.copy()
        self.seq = seq
        self.seq_valid = True

    def bridge(self, missing, dtheta_p, dv_p, encoder):
        """Interpolate the missing ticks between the last sample and this one (mirrors bridge)."""
        dtheta0 = self.last_dtheta
        dv0 = self.last_dv
        ddtheta = dtheta_p - dtheta0
        ddv = dv_p - dv0
        enc0 = self.encoder
        turn = wrap_pi(encoder - enc0)
        span = float(missing + 1)
        for j in range(1, missing + 1):
            f = float(j) / span
            self.advance(dtheta0 + ddtheta * f, dv0 + ddv * f, wrap_two_pi(enc0 + turn * f))

    def advance(self, dtheta_p, dv_p, encoder):
        """One tick with increments taken as good (mirrors Firmware::advance)."""
        # 1. Unwrap the encoder: the table turns far less than pi per tick.
        dalpha = 0.0
        if encoder != self.encoder:   # the table moved: refresh the cached half-angle
            dalpha = wrap_pi(encoder - self.encoder)
            self.encoder = encoder
            self.enc_sin_half = math.sin(0.5 * self.encoder)
            self.enc_cos_half = math.cos(0.5 * self.encoder)
        self.table_angle = self.table_angle + dalpha
        # 2. Lever arm: w(t0) refined on the second tick, the rates of this one.
        if self.has_lever:
            if self.lever_refine:
                # w(t0) refined with this tick's increments (mirrors advance)
                self.lever_refine = 0
                dw = (self.prev_dtheta - dtheta_p) / (2.0 * self.dt)
                dwa = (self.prev_dalpha - dalpha) / (2.0 * self.dt)
                du = self.lever_vel_for(dw, dwa)   # u is linear in the rates
                dvel = attitude.quat_to_mat(self.sd.nav.quat_np) @ du
                if self.sd.vertical == strapdown.VERTICAL_HOLD:
                    dvel[2] = 0.0
                nav = self.sd.nav
                sin_lat, cos_lat = np.sin(nav.lat), np.cos(nav.lat)
                rm, rn = earth.principal_radii(sin_lat)
                nav.vel_n = nav.vel_n + dvel
                nav.lat = nav.lat + dvel[1] * self.dt / (rm + nav.height)
                nav.lon = wrap_pi(nav.lon + dvel[0] * self.dt / ((rn + nav.height) * cos_lat))
                if self.sd.vertical == strapdown.VERTICAL_FREE:
                    nav.height = nav.height + dvel[2] * self.dt
        if self.rates_on:
            self.update_rates(dtheta_p, dalpha)
        # 3. An alignment restart (a sample rejected or missing) begins here.
        if self.gap_pending:
            self.gap_pending = False
            self.align_restarts = self.align_restarts + 1
            if self.cfg["coarse_ticks"] > 0:
                self.coarse = coarse_align.init(self.coarse.prm)
                self.att_valid = False
                self.mode = abi.PYINS_MODE_COARSE_ALIGN
            else:
                self.start_fine()
        # 4. The first sample leaves IDLE for the first configured mode.
        if self.mode == abi.PYINS_MODE_IDLE:
            if self.cfg["coarse_ticks"] > 0:
                self.mode = abi.PYINS_MODE_COARSE_ALIGN
            elif self.cfg["fine_ticks"] > 0:
                self.start_fine()
            else:
                self.start_navigation()
                if self.has_lever:
                    self.place_imu(self.cfg["lat_rad"], self.sd.ref_lon, self.cfg["height_m"],
                                   np.array(self.cfg["vel_n_mps"], dtype=float))
                    self.lever_refine = 1
        # 5. The mode's work: coarse alignment, moving-base or static fine
        #    alignment, or navigation with the indexing cycle.
        if self.mode == abi.PYINS_MODE_COARSE_ALIGN:
            coarse_align.update(self.coarse, dtheta_p, dv_p,
                                self.lever_vel_p() if self.has_lever else np.zeros(3), self.gnss_lever_vel_p())
            # under way the noise's own wander is allowed (coarse_align.hpp, "Under way")
            wander_max = self.coarse_wander_max
            noise_wander = coarse_align.WANDER_SIGMAS * self.coarse.settle_sigma
            if noise_wander >= 0.5 * np.pi:
                wander_max = 1.0
            elif math.sin(noise_wander) > wander_max:
                wander_max = math.sin(noise_wander)
            if self.coarse.wander > wander_max:
                self.faults = self.faults | abi.PYINS_FAULT_COARSE_UNSETTLED
                self.integrity_lost = 1
            if self.coarse.tick == self.cfg["coarse_ticks"]:
                self.end_coarse()
        elif self.mode == abi.PYINS_MODE_FINE_ALIGN and self.kf_states == 12:
            self.moving_fine(dtheta_p, dv_p)
        elif self.mode == abi.PYINS_MODE_FINE_ALIGN:
            dv_sf_n = strapdown.update(self.sd, dtheta_p, dv_p, self.dt)
            self.hold_at_site()
            if self.has_lever:
                lat = self.cfg["lat_rad"]
                w_ie_n = np.array([0.0, earth.OMEGA_IE * np.cos(lat), earth.OMEGA_IE * np.sin(lat)])
                lv = attitude.quat_to_mat(self.sd.nav.quat_np) @ self.lever_vel_p()
                dv_sf_n = dv_sf_n - (lv - self.lever_vel_n) - cross(w_ie_n, lv) * self.dt
                self.lever_vel_n = lv
            updated = fine_align.step(self.fine, dv_sf_n)
            if not self.fine.healthy:
                self.faults = self.faults | abi.PYINS_FAULT_KF_NOT_PD
            if not self.fine.consistent:
                self.faults = self.faults | abi.PYINS_FAULT_ALIGN_INCONSISTENT
                self.integrity_lost = 1
            if updated and self.cfg["fine_correction"] == abi.PYINS_FINE_FEEDBACK:
                self.apply_fine_correction()
            self.fine_tick = self.fine_tick + 1
            if self.fine_tick == self.cfg["fine_ticks"]:
                self.end_fine()
        else:
            if self.nav_on:
                # the biases, scale factors and misalignments the filter
                # estimated, compensated (0 until it has)
                dtheta_c = nav_filter.compensate_gyro(self.nav, dtheta_p, self.dt)
                dv_sf_n = strapdown.update(self.sd, dtheta_c, dv_p - self.nav.accel_bias * self.dt, self.dt)
                self.nav_tick(dv_sf_n, dtheta_c)
                self.blend_tick()
            else:
                strapdown.update(self.sd, dtheta_p, dv_p, self.dt)
            if self.index_prm.n_steps > 0:
                sn = cs = 0.0
                if indexing.wants_heading(self.idx):
                    sn, cs = self.imu_yaw_sincos()
                indexing.update(self.idx, self.table_angle, sn, cs)
        # 6. The tick, and the references that belong to it.
        self.tick = self.tick + 1
        if self.refq:
            self.refs_due()

    def solution(self):
        """(lat, lon, height, vel, q_np, q_nb, state_flags): what output()
        and nav_record() both report."""
        nav = self.sd.nav
        lat, lon, height, vel = nav.lat, nav.lon, nav.height, nav.vel_n.copy()
        if self.has_lever and self.mode in (abi.PYINS_MODE_FINE_ALIGN, abi.PYINS_MODE_NAVIGATE):
            lat, lon, height, vel = self.reference_point()
            if self.sd.vertical == strapdown.VERTICAL_HOLD:
                vel[2] = 0.0
        if self.blend_on and self.mode == abi.PYINS_MODE_NAVIGATE:
            # the bumpless return: the output offset (mirrors solution)
            lat = lat + self.out_off[0]
            lon = wrap_pi(lon + self.out_off[1])
            vel[0] = vel[0] + self.out_off[2]
            vel[1] = vel[1] + self.out_off[3]
        q_np = nav.quat_np
        valid = self.att_valid
        if self.mode == abi.PYINS_MODE_COARSE_ALIGN and self.coarse.solved:
            q_np = attitude.mat_to_quat(coarse_align.mat_n_p(self.coarse))
            valid = False   # provisional until the alignment ends and its wander test passed
        elif self.mode == abi.PYINS_MODE_FINE_ALIGN:
            q_np = attitude.quat_renormalize(
                attitude.quat_mul(attitude.rotvec_to_quat(self.fine_phi()), nav.quat_np))
            if ((self.cfg["integrity_nis_window"] > 0 and self.fine.nis_windows == 0)
                    or not self.fine_heading_known()):
                valid = False   # provisional until the first NIS window, and the heading known
        elif (self.mode == abi.PYINS_MODE_NAVIGATE and self.nav_on and self.kf_states == 0
              and self.cfg["coarse_ticks"] > 0 and not self.nav_heading_known() and self.ref_aided()):
            valid = False   # the navigation filter on a coarse attitude: once 3 sigma is within 10'
        state_flags = abi.PYINS_STATE_ATT_VALID if valid and not self.integrity_lost else 0
        if self.mode == abi.PYINS_MODE_NAVIGATE and self.refs_in_use() & (1 << (abi.PYINS_REF_GNSS_POS - 1)):
            state_flags = state_flags | abi.PYINS_STATE_POS_AIDED
        q_nb = attitude.quat_renormalize(attitude.quat_mul_z(q_np, self.enc_cos_half, -self.enc_sin_half))
        return lat, lon, height, vel, q_np.copy(), q_nb, state_flags

    def nav_record(self):
        lat, lon, height, vel, q_np, q_nb, state_flags = self.solution()
        return {
            "tick": self.tick,
            "mode": self.mode,
            "fault_flags": self.faults,
            "state_flags": state_flags,
            "index_state": self.idx.state,
            "nav_mode": self.nav_mode_now(),
            "ref_in_use": self.refs_in_use() if self.mode == abi.PYINS_MODE_NAVIGATE else 0,
            "lat_rad": lat,
            "lon_rad": lon,
            "height_m": height,
            "vel_n_mps": vel,
            "quat_nb": q_nb,
            "quat_np": q_np,
            "table_angle_rad": self.table_angle,
            "motor_rate_cmd_rad_s": self.idx.cmd_rate,
            "table_angle_cmd_rad": self.idx.cmd_angle,
        }

    def output(self):
        out = self.nav_record()      # the fields both records share, from solution()
        euler_b = attitude.quat_to_euler(out["quat_nb"])
        return {
            **out,
            "euler_b_rad": euler_b,
            "heading_b_rad": attitude.yaw_to_heading(euler_b[2]),
            "yaw_p_rad": wrap_pi(euler_b[2] + self.encoder),
            "index_step": self.idx.step,
            "index_fault": self.idx.fault,
            "index_fallbacks": self.idx.fallbacks,
            "index_a_c": self.idx.a_c,
            "index_a_s": self.idx.a_s,
            "index_travel_rad": self.idx.travel,
            "index_motor_starts": self.idx.motor_starts,
            "kf_states": self.kf_states,
            "align_restarts": self.align_restarts,
            **self.counts,
            "seq": self.seq,
            "align_nis": self.fine.nis_mean if self.fine is not None else 0.0,
            "coarse_wander_rad": self.coarse.wander if self.cfg["coarse_ticks"] > 0 else 0.0,
            "coarse_vrw": coarse_align.measured_vrw(self.coarse) if self.cfg["coarse_ticks"] > 0 else 0.0,
            "fine_vrw": self.fine_vrw if self.kf_states in (5, 8) else 0.0,
            "kf_x": self._kf(lambda f: f.x),
            "kf_sigma": self._kf(lambda f: np.sqrt(np.diag(f.p))),
            **self.nav_output(),
        }

    def _kf(self, get):
        out = np.zeros(8)
        if self.fine is not None:
            v = get(self.fine)
            if len(v) == moving_align.STATES:    # [phi, eps, nabla_E, nabla_N], as the 8-state filter
                v = v[[0, 1, 2, moving_align.EPS, moving_align.EPS + 1, moving_align.EPS + 2,
                       moving_align.NABLA, moving_align.NABLA + 1]]
            out[:len(v)] = v
        return out

    def run(self, dtheta_p, dv_p, table_angle_rad, seq=None):
        """Step through arrays; returns a list of output dicts (raises at a rejected sample)."""
        outs = []
        for k in range(len(dtheta_p)):
            status, out = self.step(dtheta_p[k], dv_p[k], table_angle_rad[k], 0 if seq is None else seq[k])
            if status < 0:
                raise ValueError(f"sample {k} rejected with status {status}")
            outs.append(out)
        return outs
