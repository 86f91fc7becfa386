"""The firmware at sea: the navigation filter beside the strapdown in
NAVIGATE and the external references (``push_ref``).

Mirrors ``csrc/src/firmware_nav.cpp`` (the Firmware members firmware.hpp
declares under "Navigation at sea"), function by function: `NavAtSea` is
mixed into `pyins.reference.firmware.Firmware` and works on its state.
"""
import math

import numpy as np

from . import abi, attitude, coarse_align, config, earth, fine_align, nav_filter
from .angle import wrap_pi

REF_QUEUE = 8       #: kRefQueue
REF_KINDS = 5       #: kRefKinds
REF_IN_USE_S = 10   #: kRefInUseS
DAMPING_RATIO = 0.707                   #: kDampingRatio
TURN_TAU = 20.0                         #: kTurnTau [s]
STRAIGHT_RATE = 0.3 * math.pi / 180.0   #: kStraightRate [rad/s]
STRAIGHT_S = 10                         #: kStraightS
CURRENT_READINGS = 60                   #: kCurrentReadings
BLEND_MIN_M = 10.0                      #: kBlendMinM
BLEND_MIN_MPS = 0.1                     #: kBlendMinMps
BLEND_WINDOW_S = 10                     #: kBlendWindowS
BLEND_TAU = 60.0                        #: kBlendTau [s]
BLEND_SPEED = 0.5                       #: kBlendSpeed [m/s]
BLEND_ACCEL = 0.002                     #: kBlendAccel [m/s^2]
BLEND_DONE_M = 1e-3                     #: kBlendDoneM
BLEND_DONE_MPS = 1e-5                   #: kBlendDoneMps
LOG_MIN_HORIZONTAL = 0.5                #: kLogMinHorizontal
U32 = 0xFFFFFFFF


def count(counter, n=1):
    """counter + n, saturating at 2^32 - 1 (mirrors count)."""
    return U32 if n > U32 - counter else counter + n


class NavAtSea:
    """The navigation-at-sea members of the firmware (mixin)."""

    def init_nav(self):
        """The members firmware.cpp's init sets for this part."""
        self.nav_on = 0
        self.refq = []                 # the queue (the C++ ring, oldest first)
        self.ref_last_tick = -1
        self.nav = None
        self.n_ref_used = [0] * REF_KINDS
        self.n_ref_rejected = [0] * REF_KINDS
        self.n_ref_skipped = [0] * REF_KINDS
        self.ref_reject_run = [0] * REF_KINDS
        self.ref_out = [0] * REF_KINDS
        self.ref_used_tick = [-1] * REF_KINDS
        self.nav_nis = [0.0] * REF_KINDS
        self.n_ref_stale = [0] * REF_KINDS
        self.ref_seen = [0] * REF_KINDS
        self.ref_seen_tick = [-1] * REF_KINDS
        self.ref_seen_value = [(0.0, 0.0)] * REF_KINDS
        self.ref_seen_vel = [(0.0, 0.0)] * REF_KINDS
        # level damping by the speed log (damp_interval, apply_log)
        self.log_speed = 0.0
        self.current_n = [0.0, 0.0]
        self.bow_last = [0.0, 0.0]
        self.turn_rate_f = 0.0
        self.damp_int = [0.0, 0.0]
        self.current_known = 0
        self.straight_s = 0
        self.bow_known = 0
        self.damp_on = 0
        self.damp_ref = [(0.0, 0.0)] * REF_KINDS
        # the bumpless return (blend_tick, solution)
        self.out_off = [0.0, 0.0, 0.0, 0.0]
        self.blend_m_rad = (0.0, 0.0)
        self.blend_window = 0
        self.blend_on = 0

    def start_nav_filter(self):
        cfg = self.cfg
        kf_sigma = self._kf(lambda f: np.sqrt(np.diag(f.p)))
        # after a coarse alignment alone: the sigmas left 0 fitted to the coarse
        # result (fine_align.sigma0_after_coarse, capped at the defaults)
        fitted = np.array(cfg["fine_sigma0_att_rad"], dtype=float)
        if self.kf_states == 0 and cfg["coarse_ticks"] > 0:
            sin_lat, cos_lat = math.sin(cfg["lat_rad"]), math.cos(cfg["lat_rad"])
            fp = fine_align.Params(
                sin_lat=sin_lat, cos_lat=cos_lat, gravity=earth.normal_gravity(sin_lat, cfg["height_m"]),
                dt=self.dt, meas_every=cfg["fine_meas_every_ticks"], gyro_arw=cfg["fine_gyro_arw"],
                accel_vrw=cfg["fine_accel_vrw"], sigma0_att=fitted.copy(), sigma0_gyro=cfg["fine_sigma0_gyro"],
                sigma0_accel=cfg["fine_sigma0_accel"], nis_window=0, nis_max=0.0)
            measured = coarse_align.measured_vrw(self.coarse)
            if measured > fp.accel_vrw:
                fp.accel_vrw = measured
            fine_align.sigma0_after_coarse(fp, float(cfg["coarse_ticks"]) * self.dt, self.coarse.wander,
                                           config.DEFAULT_FINE_SIGMA_ATT)
            fitted = fp.sigma0_att
            if self.coarse.prm.method == coarse_align.METHOD_FIT_VEL and cfg["fine_sigma0_att_rad"][2] == 0.0:
                # under way the reference velocity's noise adds its heading sigma
                # (coarse_align.hpp, "Under way"), with the same margin
                h = fine_align.AFTER_COARSE_MARGIN * self.coarse.sigma_heading
                v = math.sqrt(fitted[2] * fitted[2] + h * h)
                if v > config.DEFAULT_FINE_SIGMA_ATT[2]:
                    v = config.DEFAULT_FINE_SIGMA_ATT[2]
                fitted[2] = v
        att = np.zeros(3)
        for i in range(3):
            configured = fitted[i] if fitted[i] > 0.0 else config.DEFAULT_FINE_SIGMA_ATT[i]
            att[i] = kf_sigma[i] if self.kf_states != 0 else configured
        prm = nav_filter.Params(
            dt=self.dt, every=cfg["nav_every_ticks"], reject_limit=cfg["nav_reject_limit"],
            gyro_arw=cfg["fine_gyro_arw"], accel_vrw=cfg["fine_accel_vrw"], gate=cfg["nav_gate"],
            sigma0_att=att, sigma0_vel=config.NAV_SIGMA0_VEL, sigma0_pos=config.NAV_SIGMA0_POS,
            sigma0_gyro=cfg["fine_sigma0_gyro"], sigma0_accel=cfg["fine_sigma0_accel"],
            gyro_bias_rw=cfg["nav_gyro_bias_rw"], table_scale=cfg["nav_table_scale_sigma"],
            table_mis=cfg["nav_table_mis_sigma"], level_scale=cfg["nav_level_scale_sigma"],
            level_mis=cfg["nav_level_mis_sigma"])
        self.nav = nav_filter.init(prm, attitude.quat_to_mat(self.sd.nav.quat_np))
        self.nav_on = 1
        self.out_off = [0.0, 0.0, 0.0, 0.0]
        self.blend_m_rad = (0.0, 0.0)
        self.blend_window = 0
        self.blend_on = 0

    def nav_motion(self):
        nav = self.sd.nav
        sin_lat, cos_lat = math.sin(nav.lat), math.cos(nav.lat)
        rm, rn = earth.principal_radii(sin_lat)
        return nav_filter.Motion(sin_lat, cos_lat, rm + nav.height, rn + nav.height,
                                 float(nav.vel_n[0]), float(nav.vel_n[1]))

    def nav_tick(self, dv_sf_n, dtheta_c):
        nav_filter.gather(self.nav, dv_sf_n, dtheta_c)
        if self.nav.ticks == self.nav.prm.every:
            nav_filter.predict(self.nav, self.nav_motion(), attitude.quat_to_mat(self.sd.nav.quat_np))
            if self.nav.healthy == 0:
                self.faults = self.faults | abi.PYINS_FAULT_KF_NOT_PD
            self.damp_interval()

    def blend_offset_m(self):
        """The output offset's position part in metres, (E, N), by the radii where
        it was taken (mirrors blend_offset_m)."""
        return self.out_off[1] * self.blend_m_rad[0], self.out_off[0] * self.blend_m_rad[1]

    def blend_tick(self):
        """The output offset's decay, once a tick in NAVIGATE (mirrors blend_tick)."""
        if self.blend_window > 0:
            self.blend_window -= 1
        if not self.blend_on:
            return
        a = self.dt / BLEND_TAU
        de, dn = self.blend_offset_m()
        d = math.sqrt(de * de + dn * dn)
        sp = a
        if d * sp > BLEND_SPEED * self.dt:
            sp = BLEND_SPEED * self.dt / d
        o = self.out_off
        v = math.sqrt(o[2] * o[2] + o[3] * o[3])
        sv = a
        if v * sv > BLEND_ACCEL * self.dt:
            sv = BLEND_ACCEL * self.dt / v
        self.out_off = [o[0] * (1.0 - sp), o[1] * (1.0 - sp), o[2] * (1.0 - sv), o[3] * (1.0 - sv)]
        if d < BLEND_DONE_M and v < BLEND_DONE_MPS:
            self.out_off = [0.0, 0.0, 0.0, 0.0]
            self.blend_on = 0

    def reject_ref(self, slot):
        """A reference failed its gate (mirrors reject_ref)."""
        self.n_ref_rejected[slot] = count(self.n_ref_rejected[slot])
        if self.ref_reject_run[slot] < self.cfg["nav_reject_limit"]:
            self.ref_reject_run[slot] += 1
        if self.ref_reject_run[slot] == self.cfg["nav_reject_limit"]:
            self.ref_out[slot] = 1
            self.faults = self.faults | abi.PYINS_FAULT_REF_REJECTED

    def use_ref(self, slot):
        """A reference passed its gate (mirrors use_ref)."""
        self.ref_reject_run[slot] = 0
        self.ref_out[slot] = 0
        self.n_ref_used[slot] = count(self.n_ref_used[slot])
        self.ref_used_tick[slot] = self.tick

    def ref_point_vel(self):
        vel = self.sd.nav.vel_n
        if self.has_lever:
            vel = self.reference_point()[3]
        return float(vel[0]), float(vel[1])

    def apply_log(self, value, sigma, slot):
        """The EM log: a damping reference, not a filter measurement (mirrors apply_log)."""
        be, bn, hb = self.bow_n(horizontal=True)
        # the log reads along the pitching hull axis: its horizontal part (mirrors apply_log)
        if not hb > LOG_MIN_HORIZONTAL:
            self.reject_ref(slot)
            return
        ve, vn = self.ref_point_vel()
        v_h = value[0] / hb
        if self.current_known == 0:
            self.current_n = [ve - v_h * be, vn - v_h * bn]
        innov = (ve - self.current_n[0]) * be + (vn - self.current_n[1]) * bn - v_h
        p = self.nav.p
        kv = nav_filter.VEL
        pvv = p[kv, kv] * be * be + 2.0 * p[kv, kv + 1] * be * bn + p[kv + 1, kv + 1] * bn * bn
        nis = innov * innov / (sigma[0] * sigma[0] + pvv)
        self.nav_nis[slot] = nis
        if not nis <= self.cfg["nav_gate"]:
            self.reject_ref(slot)
            return
        self.use_ref(slot)
        self.log_speed = v_h
        known = ((1 << (abi.PYINS_REF_GNSS_VEL - 1)) | (1 << (abi.PYINS_REF_DVL - 1))
                 | (1 << (abi.PYINS_REF_ZERO_VEL - 1)))
        n = float(CURRENT_READINGS)
        if self.current_known < CURRENT_READINGS:
            self.current_known += 1
            n = float(self.current_known)
        elif not self.refs_in_use() & known:
            return
        self.current_n = [self.current_n[0] + (ve - v_h * be - self.current_n[0]) / n,
                          self.current_n[1] + (vn - v_h * bn - self.current_n[1]) / n]

    def point_vel_n(self, q_nb, lv):
        """How much faster than the reference point a point at the lever arm lv
        (in b) moves, in n (mirrors point_vel_n): C_b^n (w_ib^b x l) - w_ie^n x
        C_b^n l, w_ib^b = Rz(alpha) (w_ip^p - alpha' z)."""
        sa, ca = self.encoder_sincos()
        w_p = self.rate_p - np.array([0.0, 0.0, self.alpha_rate])
        w_b = np.array([ca * w_p[0] - sa * w_p[1], sa * w_p[0] + ca * w_p[1], w_p[2]])
        c_nb = attitude.quat_to_mat(q_nb)
        lb = np.array([lv[0], lv[1], lv[2]], dtype=float)
        lat = self.sd.nav.lat
        w_ie_n = np.array([0.0, earth.OMEGA_IE * math.cos(lat), earth.OMEGA_IE * math.sin(lat)])
        return c_nb @ attitude.cross(w_b, lb) - attitude.cross(w_ie_n, c_nb @ lb)

    def dvl_n(self, value, sigma):
        """A DVL reading (bottom track) as the reference point's velocity (E, N)
        and the variances of its E, N components (mirrors dvl_n, which says
        what it leaves out): v = C_b^n C_d^b v_d less the lever arm's share."""
        q_nb = self.ship_quat()
        m = self.cfg["dvl_align_rad"]
        c_nd = attitude.quat_to_mat(attitude.quat_mul(q_nb, attitude.rotvec_to_quat(
            np.array([m[0], m[1], m[2]], dtype=float))))
        v = c_nd @ np.array([value[0], value[1], value[2]], dtype=float)
        lv = self.cfg["dvl_lever_b_m"]
        if lv[0] != 0.0 or lv[1] != 0.0 or lv[2] != 0.0:
            v = v - self.point_vel_n(q_nb, lv)
        s0, s1, s2 = sigma[0] * sigma[0], sigma[1] * sigma[1], sigma[2] * sigma[2]
        r = tuple(c_nd[i, 0] * c_nd[i, 0] * s0 + c_nd[i, 1] * c_nd[i, 1] * s1 + c_nd[i, 2] * c_nd[i, 2] * s2
                  for i in range(2))
        return (float(v[0]), float(v[1])), r

    def damp_interval(self):
        """The course's turn rate and, in DAMPED, the level damping (mirrors damp_interval)."""
        t = float(self.nav.prm.every) * self.dt
        be, bn = self.bow_n()
        if self.bow_known:
            rate = (self.bow_last[1] * be - self.bow_last[0] * bn) / t
            self.turn_rate_f = self.turn_rate_f + (rate - self.turn_rate_f) * (t / TURN_TAU)
        self.bow_last = [be, bn]
        self.bow_known = 1
        if abs(self.turn_rate_f) < STRAIGHT_RATE:
            if self.straight_s < STRAIGHT_S:
                self.straight_s += 1
        else:
            self.straight_s = 0
        self.damp_on = 1 if self.nav_mode_now() == abi.PYINS_NAV_DAMPED else 0
        if not self.damp_on:
            return
        # level damping: the third-order network (firmware_nav.cpp gives the gains)
        m = self.nav_motion()
        g = earth.normal_gravity(m.sin_lat, self.sd.nav.height)
        w_s = math.sqrt(g / math.sqrt(m.rm_h * m.rn_h))
        k1 = (1.0 + 2.0 * DAMPING_RATIO) * w_s
        k2 = 2.0 * DAMPING_RATIO
        k3 = w_s
        ve, vn = self.ref_point_vel()
        # v_ref: the log's v_h b + c, or the damping reference's (damp_ref_kind)
        kind = self.damp_ref_kind()
        re, rn = self.log_speed * be + self.current_n[0], self.log_speed * bn + self.current_n[1]
        if kind != abi.PYINS_REF_SPEED_LOG:
            re, rn = self.damp_ref[kind - 1]
        e_e = ve - re
        e_n = vn - rn
        self.damp_int = [self.damp_int[0] + k3 * t * e_e, self.damp_int[1] + k3 * t * e_n]
        dphi = np.array([-(k2 * e_n + self.damp_int[1]) * t / m.rm_h, (k2 * e_e + self.damp_int[0]) * t / m.rn_h,
                         0.0])
        nav = self.sd.nav
        nav.quat_np = attitude.quat_normalize(attitude.quat_mul(attitude.rotvec_to_quat(-dphi), nav.quat_np))
        nav.vel_n[0] = nav.vel_n[0] - k1 * t * e_e
        nav.vel_n[1] = nav.vel_n[1] - k1 * t * e_n

    def push_ref(self, kind, tick, value, sigma, reserved=0):
        """One reference; PYINS_OK or a PYINS_E_REF_* status (mirrors push_ref)."""
        cfg = self.cfg
        # UNDAMPED takes no reference; DAMPED no position (mirrors push_ref)
        if (cfg["nav_mode"] == abi.PYINS_NAV_UNDAMPED
                or (cfg["nav_mode"] == abi.PYINS_NAV_DAMPED and kind == abi.PYINS_REF_GNSS_POS)):
            return abi.PYINS_E_REF_UNUSED
        # a DVL's reserved field marks its track: bottom track (0) alone is used
        dvl = kind == abi.PYINS_REF_DVL
        if (kind not in (abi.PYINS_REF_GNSS_POS, abi.PYINS_REF_GNSS_VEL, abi.PYINS_REF_ZERO_VEL,
                         abi.PYINS_REF_SPEED_LOG, abi.PYINS_REF_DVL)
                or (dvl and reserved != 0)):
            return abi.PYINS_E_REF_KIND
        value = [float(v) for v in value]
        sigma = [float(s) for s in sigma]
        log = kind == abi.PYINS_REF_SPEED_LOG
        if (not all(math.isfinite(v) for v in value) or not (sigma[0] > 0.0) or not math.isfinite(sigma[0])
                or (not log and (not (sigma[1] > 0.0) or not math.isfinite(sigma[1])))
                or (dvl and (not (sigma[2] > 0.0) or not math.isfinite(sigma[2])))
                or (kind == abi.PYINS_REF_GNSS_POS and not abs(value[0]) <= 0.5 * math.pi)):
            return abi.PYINS_E_REF_VALUE
        if tick < self.ref_last_tick or tick < self.tick - cfg["ref_max_latency_ticks"]:
            return abi.PYINS_E_REF_ORDER
        if tick > self.tick + config.REF_HORIZON_S * cfg["tick_hz"]:
            return abi.PYINS_E_REF_FUTURE
        ref = (int(kind), int(tick), value, sigma)
        if tick > self.tick:
            if len(self.refq) == REF_QUEUE:
                return abi.PYINS_E_REF_FULL
            self.refq.append(ref)
            self.ref_last_tick = tick
            return abi.PYINS_OK
        self.ref_last_tick = tick
        if self.mode == abi.PYINS_MODE_NAVIGATE and self.nav_on:
            self.apply_ref(ref, self.tick - tick)
        else:
            self.skip_ref(ref)
        return abi.PYINS_OK

    def skip_ref(self, ref):
        """Counted as skipped; during an alignment a velocity that says the
        site moves ends its integrity (mirrors skip_ref)."""
        kind, tick, value, sigma = ref
        self.n_ref_skipped[kind - 1] = count(self.n_ref_skipped[kind - 1])
        if self.mode == abi.PYINS_MODE_COARSE_ALIGN and self.coarse.prm.method == coarse_align.METHOD_FIT_VEL:
            # under way: the velocity is the alignment's measurement, its tick
            # counted from the alignment's start (self.tick - coarse.tick)
            if kind == abi.PYINS_REF_GNSS_VEL:
                sig = sigma[0] if sigma[0] > sigma[1] else sigma[1]
                # the vertical where the receiver measured one (sigma[2] > 0, finite)
                vu = value[2] if sigma[2] > 0.0 and math.isfinite(sigma[2]) else 0.0
                coarse_align.reference(self.coarse, value[0], value[1], vu, sig,
                                       tick - (self.tick - self.coarse.tick))
            return
        if (self.mode not in (abi.PYINS_MODE_COARSE_ALIGN, abi.PYINS_MODE_FINE_ALIGN)
                or kind not in (abi.PYINS_REF_GNSS_VEL, abi.PYINS_REF_DVL)):
            return
        gnss = kind == abi.PYINS_REF_GNSS_VEL
        lv = self.cfg["gnss_lever_b_m"] if gnss else self.cfg["dvl_lever_b_m"]
        speed_sq = value[0] * value[0] + value[1] * value[1]
        sig = sigma[0] if sigma[0] > sigma[1] else sigma[1]
        if not gnss:
            speed_sq = speed_sq + value[2] * value[2]
            sig = sig if sig > sigma[2] else sigma[2]
        lever_speed = 0.0
        if self.rates_on:
            w = self.rate_p
            w_sq = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
            lever_speed = math.sqrt(w_sq * (lv[0] * lv[0] + lv[1] * lv[1] + lv[2] * lv[2]))
        bound = config.ALIGN_MAX_SPEED + 3.0 * sig + lever_speed
        if speed_sq > bound * bound:
            self.faults = self.faults | abi.PYINS_FAULT_ALIGN_INCONSISTENT
            self.integrity_lost = 1

    def refs_due(self):
        while self.refq and self.refq[0][1] <= self.tick:
            ref = self.refq.pop(0)
            if self.mode == abi.PYINS_MODE_NAVIGATE and self.nav_on:
                self.apply_ref(ref, self.tick - ref[1])
            else:
                self.skip_ref(ref)

    def apply_ref(self, ref, lag):
        kind, _, value, sigma = ref
        slot = kind - 1
        if kind == abi.PYINS_REF_SPEED_LOG:
            self.apply_log(value, sigma, slot)
            return
        m = self.nav_motion()
        nav_filter.predict(self.nav, m, attitude.quat_to_mat(self.sd.nav.quat_np))
        nav = self.sd.nav
        lat, lon, vel = nav.lat, nav.lon, nav.vel_n.copy()
        if self.has_lever:
            lat, lon, _, vel = self.reference_point()
        # the GNSS antenna at gnss_lever_b_m (mirrors apply_ref)
        la = self.cfg["gnss_lever_b_m"]
        antenna = (kind in (abi.PYINS_REF_GNSS_POS, abi.PYINS_REF_GNSS_VEL)
                   and (la[0] != 0.0 or la[1] != 0.0 or la[2] != 0.0))
        ant_n = np.zeros(3)
        vel_rp = vel.copy()
        if antenna:
            q_nb = self.ship_quat()
            ant_n = attitude.quat_to_mat(q_nb) @ np.array([la[0], la[1], la[2]], dtype=float)
            vel = vel + self.point_vel_n(q_nb, la)
        r = (sigma[0] * sigma[0], sigma[1] * sigma[1])
        k = nav_filter.VEL
        if kind == abi.PYINS_REF_GNSS_POS:
            lag_s = float(lag) * self.dt
            z = (wrap_pi(lon - value[1]) * m.rn_h * m.cos_lat - vel[0] * lag_s,
                 (lat - value[0]) * m.rm_h - vel[1] * lag_s)
            if antenna:
                z = (z[0] + ant_n[0], z[1] + ant_n[1])
            k = nav_filter.POS
        elif kind == abi.PYINS_REF_GNSS_VEL:
            z = (vel[0] - value[0], vel[1] - value[1])
        elif kind == abi.PYINS_REF_DVL:
            # a velocity pair like GNSS velocity's, from the DVL's axes (dvl_n)
            v_dvl, r = self.dvl_n(value, sigma)
            z = (vel[0] - v_dvl[0], vel[1] - v_dvl[1])
        else:
            z = (vel[0], vel[1])
        nis = nav_filter.nis_pair(self.nav, k, z, r)
        self.nav_nis[slot] = nis
        # a frozen receiver: the last value repeated while the ship moved (mirrors apply_ref)
        stale = False
        repeat = bool(kind != abi.PYINS_REF_ZERO_VEL and self.ref_seen[slot]
                      and value[0] == self.ref_seen_value[slot][0]
                      and value[1] == self.ref_seen_value[slot][1])
        if repeat:
            sigma_max = sigma[0] if sigma[0] > sigma[1] else sigma[1]
            if kind == abi.PYINS_REF_GNSS_POS:
                span = float(ref[1] - self.ref_seen_tick[slot]) * self.dt
                moved = math.sqrt(vel[0] * vel[0] + vel[1] * vel[1]) * span
            else:
                de = vel[0] - self.ref_seen_vel[slot][0]
                dn = vel[1] - self.ref_seen_vel[slot][1]
                moved = math.sqrt(de * de + dn * dn)
            stale = moved > 3.0 * sigma_max
        if not repeat:
            self.ref_seen[slot] = 1
            self.ref_seen_tick[slot] = ref[1]
            self.ref_seen_value[slot] = (value[0], value[1])
            self.ref_seen_vel[slot] = (float(vel[0]), float(vel[1]))
        if repeat:
            self.n_ref_stale[slot] = count(self.n_ref_stale[slot])
            if not stale:
                return
        if stale or not nis <= self.cfg["nav_gate"]:
            self.reject_ref(slot)
            return
        self.use_ref(slot)
        if self.cfg["nav_mode"] == abi.PYINS_NAV_DAMPED:
            # a damping reference: the reference point's ground velocity it stands for
            self.damp_ref[slot] = (float(vel_rp[0] - z[0]), float(vel_rp[1] - z[1]))
            return
        nav_filter.update_pair(self.nav, k, z, r)
        if self.nav.healthy == 0:
            self.faults = self.faults | abi.PYINS_FAULT_KF_NOT_PD
        x = self.nav.x
        phi = x[nav_filter.PHI:nav_filter.PHI + 3]
        nav.quat_np = attitude.quat_normalize(attitude.quat_mul(attitude.rotvec_to_quat(phi), nav.quat_np))
        nav.vel_n[0] = nav.vel_n[0] - x[nav_filter.VEL]
        nav.vel_n[1] = nav.vel_n[1] - x[nav_filter.VEL + 1]
        nav.lat = nav.lat - x[nav_filter.POS + 1] / m.rm_h
        nav.lon = wrap_pi(nav.lon - x[nav_filter.POS] / (m.rn_h * m.cos_lat))
        # a correction that would be a jump opens the window (mirrors apply_ref)
        dp = math.sqrt(x[nav_filter.POS] * x[nav_filter.POS] + x[nav_filter.POS + 1] * x[nav_filter.POS + 1])
        dv = math.sqrt(x[nav_filter.VEL] * x[nav_filter.VEL] + x[nav_filter.VEL + 1] * x[nav_filter.VEL + 1])
        if dp > BLEND_MIN_M or dv > BLEND_MIN_MPS:
            self.blend_window = BLEND_WINDOW_S * self.cfg["tick_hz"]
        if self.blend_window > 0:
            # the output stays where it was: the correction goes into its offset
            o = self.out_off
            self.out_off = [o[0] + x[nav_filter.POS + 1] / m.rm_h, o[1] + x[nav_filter.POS] / (m.rn_h * m.cos_lat),
                            o[2] + x[nav_filter.VEL], o[3] + x[nav_filter.VEL + 1]]
            self.blend_m_rad = (m.rn_h * m.cos_lat, m.rm_h)
            self.blend_on = 1
        nav_filter.reset_feedback(self.nav)
        self.nav.c_start = attitude.quat_to_mat(nav.quat_np)

    def nav_mode_now(self):
        if self.mode != abi.PYINS_MODE_NAVIGATE:
            return 0
        if self.cfg["nav_mode"] == abi.PYINS_NAV_DAMPED:
            return abi.PYINS_NAV_DAMPED if self.damp_ref_kind() != 0 else abi.PYINS_NAV_UNDAMPED
        in_use = self.refs_in_use() if self.nav_on else 0
        log = 1 << (abi.PYINS_REF_SPEED_LOG - 1)
        if in_use & ~log:
            return abi.PYINS_NAV_INTEGRATED
        if in_use & log and self.straight_s >= STRAIGHT_S and self.current_known >= CURRENT_READINGS:
            return abi.PYINS_NAV_DAMPED
        return abi.PYINS_NAV_UNDAMPED

    def damp_ref_kind(self):
        """The reference that damps in nav_mode DAMPED, by the override order
        GNSS velocity, log (straight course, current learnt), DVL, zero
        velocity; 0 if none (mirrors damp_ref_kind)."""
        in_use = self.refs_in_use() if self.nav_on else 0
        for kind in (abi.PYINS_REF_GNSS_VEL, abi.PYINS_REF_SPEED_LOG, abi.PYINS_REF_DVL, abi.PYINS_REF_ZERO_VEL):
            if not in_use & (1 << (kind - 1)):
                continue
            if kind == abi.PYINS_REF_SPEED_LOG and (self.straight_s < STRAIGHT_S
                                                    or self.current_known < CURRENT_READINGS):
                continue
            return kind
        return 0

    def refs_in_use(self):
        window = REF_IN_USE_S * self.cfg["tick_hz"]
        bits = 0
        for i in range(REF_KINDS):
            if self.ref_used_tick[i] >= 0 and self.tick - self.ref_used_tick[i] <= window and not self.ref_out[i]:
                bits = bits | (1 << i)
        return bits

    def nav_output(self):
        """The record's navigation-at-sea fields (mirrors the end of output())."""
        on = self.nav_on != 0
        p = self.nav.p if on else None
        # the output's sigma takes in the output offset's distance (mirrors output())
        off2 = 0.0
        if self.blend_on:
            de, dn = self.blend_offset_m()
            off2 = de * de + dn * dn
        return {
            "nav_mode": self.nav_mode_now(),
            "ref_in_use": self.refs_in_use() if self.mode == abi.PYINS_MODE_NAVIGATE else 0,
            "n_ref_used": np.array(self.n_ref_used),
            "n_ref_rejected": np.array(self.n_ref_rejected),
            "n_ref_skipped": np.array(self.n_ref_skipped),
            "n_ref_stale": np.array(self.n_ref_stale),
            "nav_nis": np.array(self.nav_nis),
            "nav_sigma_pos_m": math.sqrt(p[nav_filter.POS, nav_filter.POS]
                                         + p[nav_filter.POS + 1, nav_filter.POS + 1] + off2) if on else 0.0,
            "nav_sigma_heading_rad": math.sqrt(p[nav_filter.PHI + 2, nav_filter.PHI + 2]) if on else 0.0,
            "nav_gyro_bias_rad_s": self.nav.gyro_bias.copy() if on else np.zeros(3),
            "nav_table_err": self.nav.table_err.copy() if on else np.zeros(3),
            "nav_level_err": self.nav.level_err.copy() if on else np.zeros(4),
            "nav_accel_bias_mps2": self.nav.accel_bias.copy() if on else np.zeros(3),
        }
