//! The resolver itself: interactive-force-control paper eq. (26) integrated exactly per step, the inner velocity loop,
//! the limits and the safe stop, for the arms and the base at their own rates.

use super::closing::{bound_closing, ClosingBounds};
use super::error::ResolverError;
use super::limits::{clamp_norm, finite_or_max, position_limit, rate_limit, scale_chains};
use super::params::ResolverParams;
use crate::model::{RobotModel, BASE_JOINTS};

/// A late cycle integrates over at most this many nominal periods (no large velocity step).
const MAX_DT_PERIODS: f64 = 2.0;

/// The velocity commands of the last step.
#[derive(Clone, Debug, PartialEq)]
pub struct Commands {
    /// Arm joint velocities \[rad/s or m/s\], in model order of the arm joints
    /// ([`Resolver::arm_joints`]).
    pub joint_velocities: Vec<f64>,
    /// Base twist `(vx \[m/s\], vy \[m/s\], wz \[rad/s\])` in the BASE frame (a `geometry_msgs/Twist`'s
    /// linear.x, linear.y, angular.z); zero for a model without base.
    pub base_twist: [f64; 3],
}

/// Exact zero-order-hold step of `m v̇ + c v = f`: `v' = e v + phi f`.
#[derive(Clone, Copy, Debug, Default)]
struct Step {
    e: f64,
    phi: f64,
}

impl Step {
    fn new(m: f64, c: f64, dt: f64) -> Self {
        let x = c * dt / m;
        let e = (-x).exp();
        // (1 - e)/c, written so that it tends to dt/m without cancellation as c -> 0
        let phi = if x > 1e-8 { -(-x).exp_m1() / c } else { dt / m * (1.0 - 0.5 * x) };
        Self { e, phi }
    }
}

/// Per-arm-joint constants, from the model and the parameters.
#[derive(Clone, Debug, Default)]
struct ArmJoint {
    index: usize,
    inertia: f64,
    damping: f64,
    amax: f64,
    lower: f64,
    upper: f64,
}

/// The admittance torque resolver of interactive-force-control paper eq. (26):
///
/// ```text
/// M_a q̈_a + C_a q̇_a + g = τ_a*        (arm joints)
/// M_b ẍ_b + D_b ẋ_b     = τ_b*        (base: x, y, yaw, inertia and damping in the base frame)
/// ```
///
/// The virtual velocities are integrated exactly over each step (zero-order hold), pulled
/// towards the measured velocities by the inner loop, limited (velocity, position, acceleration)
/// and sent as the commands; the limited command is the new virtual state (no wind-up).
///
/// Arms and base run independently: call [`Resolver::update_arms`] at the arm rate (TOMM: 125 Hz)
/// and [`Resolver::update_base`] at the base rate (1 kHz), each with its own `dt`, from the same
/// or different threads' data; [`Resolver::update`] does both with one `dt`. Start from the robot's
/// state with [`Resolver::reset`]. All buffers are allocated by [`Resolver::new`].
#[derive(Clone, Debug)]
pub struct Resolver {
    params: ResolverParams,
    nv: usize,
    arm: Vec<ArmJoint>,
    arm_indices: Vec<usize>,
    /// Chain (arm) of each arm joint, for the direction-keeping velocity scaling.
    chain: Vec<usize>,
    chain_scale: Vec<f64>,
    /// Commanded velocity limit of each arm joint.
    vmax: Vec<f64>,
    /// Arm joints held still (the setup's `locked_joints`): command 0, no limits needed.
    held: Vec<bool>,
    /// Scratch: the virtual velocities before the limits.
    target: Vec<f64>,
    /// `1 / inertia` of each arm joint, 0 for a held one (the metric of the closing bounds).
    inverse_inertia: Vec<f64>,
    /// The closing-speed limits the arm steps meet ([`Resolver::closing_bounds_mut`]).
    closing: ClosingBounds,
    /// Cached exact-step coefficients for `arm_dt`.
    arm_steps: Vec<Step>,
    arm_dt: f64,
    base: Option<[usize; 3]>,
    base_steps: [Step; 3],
    base_dt: f64,
    /// The last commands; the base's virtual velocity is its last twist, in the BASE frame (the
    /// frame it is sent in, where its rate limit holds whatever the measured yaw does).
    commands: Commands,
}

impl Resolver {
    /// Builds the resolver for `model`: base joints by name ([`BASE_JOINTS`]), every other moving
    /// joint is an arm joint; velocity and position limits come from the URDF.
    pub fn new(model: &RobotModel, params: ResolverParams) -> Result<Self, ResolverError> {
        Self::with_held(model, params, &[])
    }

    /// [`Resolver::new`] with the joints marked in `held` (model order; shorter: the rest free)
    /// held still: their command is always 0, so a URDF without limits for them (a caster, a
    /// gripper's passive joint) is accepted.
    pub fn with_held(model: &RobotModel, params: ResolverParams, held: &[bool]) -> Result<Self, ResolverError> {
        let base = model.planar_base();
        if base.is_none() && BASE_JOINTS.iter().any(|n| model.joint_index(n).is_some()) {
            return Err(ResolverError::Model(format!(
                "a mobile base needs all of {BASE_JOINTS:?}, the model has only some of them"
            )));
        }
        let is_base = |j: usize| base.is_some_and(|b| b.contains(&j));
        let arm_indices: Vec<usize> = (0..model.nv()).filter(|&j| !is_base(j)).collect();
        // A chain (one arm) = the arm joints below one root arm joint (attached to the world or
        // to the base).
        let root = |mut j: usize| {
            while let Some(p) = model.joint_parent(j).filter(|&p| !is_base(p)) {
                j = p;
            }
            j
        };
        let mut roots: Vec<usize> = Vec::new();
        let mut chain = Vec::with_capacity(arm_indices.len());
        for &j in &arm_indices {
            let r = root(j);
            chain.push(roots.iter().position(|&x| x == r).unwrap_or_else(|| {
                roots.push(r);
                roots.len() - 1
            }));
        }
        let na = arm_indices.len();
        let arm = arm_indices.iter().map(|&index| ArmJoint { index, ..Default::default() }).collect();
        let mut r = Self {
            params: params.clone(),
            nv: model.nv(),
            arm_steps: vec![Step::default(); na],
            arm,
            chain,
            chain_scale: vec![1.0; roots.len()],
            vmax: vec![0.0; na],
            held: arm_indices.iter().map(|&j| held.get(j).copied().unwrap_or(false)).collect(),
            target: vec![0.0; na],
            inverse_inertia: vec![0.0; na],
            closing: ClosingBounds::default(),
            arm_dt: f64::NAN,
            base,
            base_steps: [Step::default(); 3],
            base_dt: f64::NAN,
            commands: Commands { joint_velocities: vec![0.0; na], base_twist: [0.0; 3] },
            arm_indices,
        };
        r.set_params(model, params)?;
        Ok(r)
    }

    /// Replaces the parameters (validated first; on error nothing changes). The virtual
    /// velocities and the last command are kept, so a gain change causes no velocity jump.
    pub fn set_params(&mut self, model: &RobotModel, params: ResolverParams) -> Result<(), ResolverError> {
        params.validate()?;
        for name in params.arm.joints.keys() {
            let ok = model.joint_index(name).is_some_and(|j| self.arm_indices.contains(&j));
            if !ok {
                return Err(ResolverError::UnknownJoint { key: format!("arm.joints.{name}"), joint: name.clone() });
            }
        }
        let limits = model.joint_limits();
        let mut joints = self.arm.clone();
        let mut vmax = self.vmax.clone();
        for ((a, vmax), &held) in joints.iter_mut().zip(&mut vmax).zip(&self.held) {
            let name = &model.joint_names()[a.index];
            let lim = &limits[a.index];
            let o = params.arm.joints.get(name).copied().unwrap_or_default();
            a.inertia = o.inertia.unwrap_or(params.arm.inertia);
            a.damping = o.damping.unwrap_or(params.arm.damping);
            a.amax = o.max_acceleration.unwrap_or(params.arm.max_acceleration);
            if held {
                (*vmax, a.lower, a.upper) = (0.0, f64::NEG_INFINITY, f64::INFINITY);
                continue;
            }
            if !(lim.velocity.is_finite() && lim.velocity > 0.0) || lim.lower.is_nan() || lim.upper.is_nan() {
                return Err(ResolverError::Model(format!(
                    "joint `{name}`: URDF velocity limit {} (must be finite and > 0) or position limits [{}, {}]",
                    lim.velocity, lim.lower, lim.upper
                )));
            }
            *vmax = lim.velocity * params.arm.velocity_limit_scale;
            a.lower = lim.lower;
            a.upper = lim.upper;
        }
        for ((w, a), &held) in self.inverse_inertia.iter_mut().zip(&joints).zip(&self.held) {
            *w = if held { 0.0 } else { 1.0 / a.inertia };
        }
        self.arm = joints;
        self.vmax = vmax;
        self.params = params;
        self.arm_dt = f64::NAN; // recompute the cached steps
        self.base_dt = f64::NAN;
        Ok(())
    }

    /// The parameters in use.
    pub fn params(&self) -> &ResolverParams {
        &self.params
    }

    /// Model indices of the arm joints, in the order of [`Commands::joint_velocities`].
    pub fn arm_joints(&self) -> &[usize] {
        &self.arm_indices
    }

    /// Model indices of the base joints (x, y, yaw), if the model has a base.
    pub fn base_joints(&self) -> Option<[usize; 3]> {
        self.base
    }

    /// Commanded velocity limit of each arm joint \[rad/s\] (URDF limit times the scale).
    pub fn arm_velocity_limits(&self) -> &[f64] {
        &self.vmax
    }

    /// Acceleration limit of each arm joint \[rad/s²\].
    pub fn arm_acceleration_limits(&self) -> impl Iterator<Item = f64> + '_ {
        self.arm.iter().map(|a| a.amax)
    }

    /// The closing-speed limits `r·q̇ ≤ b` (model joint order) that the arm steps meet before
    /// the other limits, the base moving at its measured velocity: the skin's approach bound,
    /// refreshed by the controller every cycle (`docs/resolver.md`); none by default.
    pub fn closing_bounds_mut(&mut self) -> &mut ClosingBounds {
        &mut self.closing
    }

    /// The commands of the last step.
    pub fn commands(&self) -> &Commands {
        &self.commands
    }

    /// Starts from the measured state without a jump: virtual velocities and last commands =
    /// measured velocities (`q_measured` gives the base yaw for the base-frame twist).
    pub fn reset(&mut self, q_measured: &[f64], qd_measured: &[f64]) -> Result<(), ResolverError> {
        self.check("q_measured", q_measured)?;
        self.check("qd_measured", qd_measured)?;
        for (v, a) in self.commands.joint_velocities.iter_mut().zip(&self.arm) {
            *v = qd_measured[a.index];
        }
        if let Some(b) = self.base {
            self.commands.base_twist = to_base_frame(b.map(|j| qd_measured[j]), q_measured[b[2]]);
        }
        Ok(())
    }

    /// Takes zero as the last command of every joint and of the base: zeros were sent by someone
    /// else (a watchdog), so the next step continues from zero within the acceleration limits.
    pub fn restart_from_zero(&mut self) {
        self.commands.joint_velocities.fill(0.0);
        self.commands.base_twist = [0.0; 3];
    }

    /// One step of the arms (all vectors in model order, length = number of model joints):
    /// `tau` = τ* (N m), `gravity` = g (N m, used when `arm.subtract_gravity`), measured joint
    /// positions and velocities. On invalid input the resolver takes one [`Resolver::safe_stop_arms`]
    /// step (so [`Resolver::commands`] is a safe command to send) and returns the error.
    pub fn update_arms(
        &mut self,
        tau: &[f64],
        gravity: &[f64],
        q_measured: &[f64],
        qd_measured: &[f64],
        dt_s: f64,
    ) -> Result<&Commands, ResolverError> {
        let inputs = [("tau", tau), ("gravity", gravity), ("q_measured", q_measured), ("qd_measured", qd_measured)];
        if let Err(e) = self.check_inputs(dt_s, &inputs) {
            self.safe_stop_arms(dt_s);
            return Err(e);
        }
        let dt = dt_s.min(MAX_DT_PERIODS / self.params.arm.rate_hz);
        if dt != self.arm_dt {
            for (s, a) in self.arm_steps.iter_mut().zip(&self.arm) {
                *s = Step::new(a.inertia, a.damping, dt);
            }
            self.arm_dt = dt;
        }
        let sync = -(-self.params.arm.sync_gain_per_s * dt).exp_m1();
        let g_factor = if self.params.arm.subtract_gravity { 1.0 } else { 0.0 };
        let cmd = &mut self.commands.joint_velocities;
        // Virtual dynamics into `target`: the rate limit needs the previous command.
        let target = &mut self.target;
        for (i, (a, s)) in self.arm.iter().zip(&self.arm_steps).enumerate() {
            let j = a.index;
            let v = cmd[i] + sync * (qd_measured[j] - cmd[i]);
            let f = tau[j] - g_factor * gravity[j];
            // a held joint's target is 0, so it does not scale its chain down (its limit is 0)
            target[i] = if self.held[i] { 0.0 } else { finite_or_max(s.e * v + s.phi * f) };
        }
        let base = self.base.as_ref().map_or(&[][..], |b| &b[..]);
        bound_closing(target, &self.arm_indices, &self.inverse_inertia, base, qd_measured, &self.closing);
        scale_chains(target, &self.vmax, &self.chain, &mut self.chain_scale);
        for (i, a) in self.arm.iter().enumerate() {
            let vmax = self.vmax[i];
            let v = position_limit(target[i], q_measured[a.index], a.lower, a.upper, a.amax, dt);
            // hard velocity limit last: only active when the previous command was above it
            cmd[i] = rate_limit(cmd[i], v, a.amax * dt).clamp(-vmax, vmax);
        }
        Ok(&self.commands)
    }

    /// One step of the base: `tau` = τ* (its base entries are the world-frame forces along x, y
    /// \[N\] and the yaw torque \[N m\]), measured positions (the yaw rotates between world and
    /// base frame) and velocities (world frame, as the base joints'), all in model order.
    /// A model without base leaves the zero twist. On invalid input: one
    /// [`Resolver::safe_stop_base`] step and the error.
    pub fn update_base(
        &mut self,
        tau: &[f64],
        q_measured: &[f64],
        qd_measured: &[f64],
        dt_s: f64,
    ) -> Result<&Commands, ResolverError> {
        let inputs = [("tau", tau), ("q_measured", q_measured), ("qd_measured", qd_measured)];
        if let Err(e) = self.check_inputs(dt_s, &inputs) {
            self.safe_stop_base(dt_s);
            return Err(e);
        }
        let Some([ix, iy, iyaw]) = self.base else {
            return Ok(&self.commands);
        };
        let p = &self.params.base;
        let dt = dt_s.min(MAX_DT_PERIODS / p.rate_hz);
        if dt != self.base_dt {
            for k in 0..3 {
                self.base_steps[k] = Step::new(p.inertia[k], p.damping[k], dt);
            }
            self.base_dt = dt;
        }
        let sync = -(-p.sync_gain_per_s * dt).exp_m1();
        let yaw = q_measured[iyaw];
        // eq. (26) lower row in the base frame, where M_b and D_b are constant and the command is
        // sent: the virtual velocity is the last command, pulled towards the measured one
        let prev = self.commands.base_twist;
        let measured = to_base_frame([qd_measured[ix], qd_measured[iy], qd_measured[iyaw]], yaw);
        let v: [f64; 3] = core::array::from_fn(|k| prev[k] + sync * (measured[k] - prev[k]));
        let fb = to_base_frame([tau[ix], tau[iy], tau[iyaw]], yaw);
        let s = &self.base_steps;
        let vb: [f64; 3] = core::array::from_fn(|k| finite_or_max(s[k].e * v[k] + s[k].phi * fb[k]));
        // limits: velocity, then the rate limit against the last command in the base frame (a
        // jump of the measured yaw, an odometry reset, cannot turn the command)
        let lin = clamp_norm([vb[0], vb[1]], p.max_linear_m_s);
        let w = vb[2].clamp(-p.max_angular_rad_s, p.max_angular_rad_s);
        let step = clamp_norm([lin[0] - prev[0], lin[1] - prev[1]], p.max_linear_accel_m_s2 * dt);
        let lin = clamp_norm([prev[0] + step[0], prev[1] + step[1]], p.max_linear_m_s);
        let w =
            rate_limit(prev[2], w, p.max_angular_accel_rad_s2 * dt).clamp(-p.max_angular_rad_s, p.max_angular_rad_s);
        self.commands.base_twist = [lin[0], lin[1], w];
        Ok(&self.commands)
    }

    /// The virtual inertia of eq. (26) in model order and world axes, for a hierarchy that must
    /// predict what the resolver executes: `M_a` on the arm joints, `R M_b Rᵀ` on the base (`R`
    /// the yaw rotation: `M_b` is constant in the base frame); off-diagonal entries are zero. A
    /// hierarchy solved with this `mass` and the bias `g` + [`Resolver::virtual_damping`] makes
    /// the executed acceleration its own `M_v⁻¹ Σ τ̄` (up to the zero-order hold), so a lower
    /// level cannot leak into a higher one through the mismatch between `M(q)` and `M_a`.
    pub fn virtual_mass(&self, q_measured: &[f64], mass: &mut nalgebra::DMatrix<f64>) {
        mass.fill(0.0);
        for a in &self.arm {
            mass[(a.index, a.index)] = a.inertia;
        }
        let Some(b) = self.base else { return };
        let m = Self::base_frame_to_world(q_measured[b[2]], self.params.base.inertia);
        for (r, &i) in b[..2].iter().enumerate() {
            for (k, &j) in b[..2].iter().enumerate() {
                mass[(i, j)] = m[(r, k)];
            }
        }
        mass[(b[2], b[2])] = self.params.base.inertia[2];
    }

    /// The virtual damping torque of eq. (26) in model order and world axes: `C_a v` on the arm
    /// joints, `R D_b Rᵀ v` on the base, with `v` the virtual velocity the next update starts
    /// from (the last command pulled towards `qd_measured` by the inner loop).
    pub fn virtual_damping(
        &self,
        q_measured: &[f64],
        qd_measured: &[f64],
        dt_s: f64,
        damping_torque: &mut nalgebra::DVector<f64>,
    ) {
        damping_torque.fill(0.0);
        let sync = |gain: f64| -(-gain * dt_s).exp_m1();
        let s = sync(self.params.arm.sync_gain_per_s);
        for (a, &cmd) in self.arm.iter().zip(&self.commands.joint_velocities) {
            damping_torque[a.index] = a.damping * (cmd + s * (qd_measured[a.index] - cmd));
        }
        let Some(b) = self.base else { return };
        let p = &self.params.base;
        let s = sync(p.sync_gain_per_s);
        let last = to_world_frame(self.commands.base_twist, q_measured[b[2]]);
        let v: [f64; 3] = core::array::from_fn(|k| last[k] + s * (qd_measured[b[k]] - last[k]));
        let f = Self::base_frame_to_world(q_measured[b[2]], p.damping) * nalgebra::Vector2::new(v[0], v[1]);
        for (r, &i) in b[..2].iter().enumerate() {
            damping_torque[i] = f[r];
        }
        damping_torque[b[2]] = p.damping[2] * v[2];
    }

    /// `R diag(x, y) Rᵀ`: a base-frame diagonal (the first two of `xyz`) in world axes at `yaw`.
    fn base_frame_to_world(yaw: f64, xyz: [f64; 3]) -> nalgebra::Matrix2<f64> {
        let (sn, c) = yaw.sin_cos();
        let rot = nalgebra::Matrix2::new(c, -sn, sn, c);
        rot * nalgebra::Matrix2::from_diagonal(&nalgebra::Vector2::new(xyz[0], xyz[1])) * rot.transpose()
    }

    /// [`Resolver::update_arms`] and [`Resolver::update_base`] with one `dt` (both parts at one
    /// rate). Both parts are stepped even if one fails; the first error is returned.
    pub fn update(
        &mut self,
        tau: &[f64],
        gravity: &[f64],
        q_measured: &[f64],
        qd_measured: &[f64],
        dt_s: f64,
    ) -> Result<&Commands, ResolverError> {
        let arms = self.update_arms(tau, gravity, q_measured, qd_measured, dt_s).map(|_| ());
        let base = self.update_base(tau, q_measured, qd_measured, dt_s).map(|_| ());
        arms.and(base)?;
        Ok(&self.commands)
    }

    /// One step of the safe stop of the arms: every joint command decelerates towards zero at its
    /// acceleration limit (an invalid `dt_s` counts as one nominal period). The virtual state
    /// follows, so a later valid update continues without a jump.
    pub fn safe_stop_arms(&mut self, dt_s: f64) -> &Commands {
        let dt = self.safe_dt(dt_s, self.params.arm.rate_hz);
        for (v, a) in self.commands.joint_velocities.iter_mut().zip(&self.arm) {
            *v = rate_limit(*v, 0.0, a.amax * dt);
        }
        // a joint above a lowered velocity limit (set_params) is brought within it too
        for (v, &vmax) in self.commands.joint_velocities.iter_mut().zip(&self.vmax) {
            *v = v.clamp(-vmax, vmax);
        }
        &self.commands
    }

    /// One step of the safe stop of the base: the planar velocity decelerates along its direction
    /// and the yaw rate towards zero, within the base's acceleration limits (in the base frame,
    /// where the twist is sent).
    pub fn safe_stop_base(&mut self, dt_s: f64) -> &Commands {
        let p = &self.params.base;
        let dt = self.safe_dt(dt_s, p.rate_hz);
        let t = self.commands.base_twist;
        let step = clamp_norm([-t[0], -t[1]], p.max_linear_accel_m_s2 * dt);
        let w = rate_limit(t[2], 0.0, p.max_angular_accel_rad_s2 * dt);
        self.commands.base_twist = [t[0] + step[0], t[1] + step[1], w];
        &self.commands
    }

    /// One safe-stop step of arms and base with one `dt` (see [`Resolver::safe_stop_arms`],
    /// [`Resolver::safe_stop_base`]).
    pub fn safe_stop(&mut self, dt_s: f64) -> &Commands {
        self.safe_stop_arms(dt_s);
        self.safe_stop_base(dt_s)
    }

    fn safe_dt(&self, dt_s: f64, rate_hz: f64) -> f64 {
        let nominal = 1.0 / rate_hz;
        if dt_s.is_finite() && dt_s > 0.0 {
            dt_s.min(MAX_DT_PERIODS * nominal)
        } else {
            nominal
        }
    }

    /// The period, then each named model-order vector: length and finiteness.
    fn check_inputs(&self, dt_s: f64, inputs: &[(&'static str, &[f64])]) -> Result<(), ResolverError> {
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(ResolverError::InvalidDt(dt_s));
        }
        inputs.iter().try_for_each(|&(what, x)| self.check(what, x))
    }

    fn check(&self, what: &'static str, x: &[f64]) -> Result<(), ResolverError> {
        if x.len() != self.nv {
            return Err(ResolverError::Dimension { what, expected: self.nv, got: x.len() });
        }
        match x.iter().position(|v| !v.is_finite()) {
            Some(index) => Err(ResolverError::NonFinite { what, index, value: x[index] }),
            None => Ok(()),
        }
    }
}

/// World-frame planar velocity `(vx, vy, wz)` expressed in a frame rotated by `yaw` (rotation by
/// `-yaw`); `wz` is the same in both.
fn to_base_frame(v: [f64; 3], yaw: f64) -> [f64; 3] {
    let (s, c) = yaw.sin_cos();
    [c * v[0] + s * v[1], -s * v[0] + c * v[1], v[2]]
}

/// Inverse of [`to_base_frame`].
fn to_world_frame(v: [f64; 3], yaw: f64) -> [f64; 3] {
    let (s, c) = yaw.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}
