//! The simulation's speed per scenario (`make bench`'s `scripts/bench_sim.py`): its real-time
//! factor, the factor the physics alone allows, and where each simulated second's wall time went.

use std::collections::BTreeMap;

/// The parts of the simulation loop, in `sim_ms_per_s_<part>_<scenario>` order.
pub const PARTS: [&str; 4] = ["physics", "sensors", "controller", "other"];

/// One scenario's simulation speed (its best of three runs).
#[derive(Debug, Clone, PartialEq)]
pub struct SimPoint {
    /// Scenario name.
    pub name: String,
    /// Simulated time over wall time.
    pub realtime_factor: f64,
    /// Simulated time over the time in `mj_step`: the factor with everything else at zero cost.
    pub physics_bound: f64,
    /// Wall milliseconds per simulated second in each of [`PARTS`].
    pub ms_per_s: [f64; 4],
}

/// The scenarios measured in `medians` (`out/bench/summary.json`), by name.
pub fn points(medians: &BTreeMap<String, f64>) -> Vec<SimPoint> {
    medians
        .keys()
        .filter_map(|k| k.strip_prefix("sim_physics_bound_"))
        .filter_map(|name| {
            let get = |key: String| medians.get(&key).copied();
            let mut ms_per_s = [0.0; 4];
            for (k, part) in PARTS.iter().enumerate() {
                ms_per_s[k] = get(format!("sim_ms_per_s_{part}_{name}"))?;
            }
            Some(SimPoint {
                name: name.to_string(),
                realtime_factor: get(format!("sim_realtime_factor_{name}"))?,
                physics_bound: get(format!("sim_physics_bound_{name}"))?,
                ms_per_s,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scenario_needs_every_part() {
        let mut m: BTreeMap<String, f64> = [
            ("sim_realtime_factor_a", 40.0),
            ("sim_physics_bound_a", 50.0),
            ("sim_ms_per_s_physics_a", 20.0),
            ("sim_ms_per_s_sensors_a", 4.0),
            ("sim_ms_per_s_controller_a", 0.5),
            ("sim_ms_per_s_other_a", 0.5),
            ("sim_physics_bound_tomm", 50.0),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        let p = points(&m);
        assert_eq!(p.len(), 1, "`tomm` has no parts: an aggregate, not a scenario");
        assert_eq!((p[0].name.as_str(), p[0].ms_per_s), ("a", [20.0, 4.0, 0.5, 0.5]));
        m.remove("sim_ms_per_s_sensors_a");
        assert!(points(&m).is_empty());
    }
}
