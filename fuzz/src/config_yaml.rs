//! Arbitrary text as every YAML configuration type of skin_core: task, supervisor, skin model
//! and resolver parameters, skin layouts and controller setups. Checked: no panic; whatever
//! parses passes its own `validate()`; then the parsed value replaces its part of the shipped
//! TOMM configuration and a controller is built from it (an error is fine, a panic is not) and
//! runs a few cycles (finite commands); values that must work once validated (skin
//! characteristics, the supervisor, layout resolution) are exercised.

use nalgebra::Vector2;
use skin_core::controller::{Controller, ControllerConfig, ControllerInput, ControllerSetup};
use skin_core::param_file::yaml;
use skin_core::resolver::{Resolver, ResolverParams};
use skin_core::skin::layout::{ResolvedLayout, SkinLayout};
use skin_core::skin::params::SkinParams;
use skin_core::skin::signals::CellReading;
use skin_core::supervisor::{Supervisor, SupervisorParams};
use skin_core::tasks::params::TaskParams;

use crate::fixtures::{text, tomm};

const SOURCE: &str = "fuzz.yaml";

/// Builds a controller from the shipped TOMM configuration changed by `edit` (must not panic)
/// and, if that works, runs a few cycles at the home posture with the skin touched and a laser
/// point near the base: the commands must stay finite (`ControllerOutput`'s promise).
fn build_with(edit: impl FnOnce(&mut ControllerConfig)) {
    let mut config = tomm().config.clone();
    edit(&mut config);
    let Ok(mut controller) = Controller::new(config, 0.0) else {
        return;
    };
    let shipped = &tomm().config;
    let q = &shipped.setup.posture;
    let qd = vec![0.0; q.len()];
    let cells = vec![CellReading::uniform(0.5, 0.8); shipped.layout.num_cells()];
    let scan = [Vector2::new(0.6, 0.1)];
    for k in 1..=3 {
        let input = ControllerInput { t_s: 0.008 * f64::from(k), dt_s: 0.008, q, qd: &qd, cells: &cells, scan: &scan };
        let out = controller.update(&input);
        let c = &out.commands;
        let finite = c.joint_velocities.iter().chain(&c.base_twist).all(|v| v.is_finite());
        assert!(finite, "cycle {k}: non-finite commands {c:?} (fault {:?})", out.fault);
    }
}

/// Signals, distances and forces to evaluate the characteristics at.
const PROBES: [f64; 9] = [f64::NAN, f64::NEG_INFINITY, -1.0, 0.0, 1e-300, 0.01, 0.5, 1.0, f64::INFINITY];

fn check_skin_params(p: &SkinParams) {
    p.validate().expect("parsed skin model validates");
    let (prox, force, rep) = (&p.proximity, &p.force, &p.repulsion);
    for x in PROBES.into_iter().chain([prox.range_m, force.max_n, p.repulsion.range_m]) {
        let d = prox.distance_m(x);
        assert!((0.0..=prox.range_m).contains(&d), "proximity distance_m({x}) = {d}: {p:?}");
        let f = force.force_n(x);
        assert!((0.0..=force.max_n).contains(&f), "force_n({x}) = {f}: {p:?}");
        for s in [prox.signal(x), force.signal(x)] {
            assert!((0.0..=1.0).contains(&s), "signal({x}) = {s}: {p:?}");
        }
        for r in [rep.linear_n(d), rep.exponential_n(d)] {
            assert!(r.is_finite() && r >= 0.0, "repulsion at {d} m = {r}: {p:?}");
        }
    }
    build_with(|c| c.skin = *p);
}

fn check_layout(l: &SkinLayout) {
    l.validate().expect("parsed layout validates");
    l.resolve_with(|_| Some(0)).expect("a validated layout resolves when every link exists");
    if let Ok(resolved) = l.resolve(&tomm().config.model) {
        check_resolved(&resolved);
        build_with(|c| c.layout = resolved);
    }
}

fn check_resolved(r: &ResolvedLayout) {
    let mut next = 0;
    for (k, p) in r.patches().iter().enumerate() {
        assert_eq!(p.cells.start, next, "patch {}: cells are grouped by patch", p.id);
        next = p.cells.end;
        assert_eq!(r.patch_index(p.id), Some(k));
    }
    assert_eq!(next, r.num_cells());
    for (i, c) in r.cells().iter().enumerate() {
        assert_eq!(r.cell_index(c.id), Some(i), "cell {}", c.id);
        for n in [c.normal_patch, c.normal_link] {
            assert!((n.norm() - 1.0).abs() < 1e-9, "cell {}: normal {n:?} is not a unit vector", c.id);
        }
        let poses = [c.link_from_cell.translation.vector, c.position_link, c.position_patch];
        assert!(poses.iter().all(|v| v.iter().all(|x| x.is_finite())), "cell {}: {c:?}", c.id);
    }
}

fn check_supervisor(p: &SupervisorParams) {
    p.validate().expect("parsed supervisor parameters validate");
    Supervisor::new(p, 0.0).expect("validated supervisor parameters build a supervisor");
    build_with(|c| c.supervisor = p.clone());
}

fn check_resolver(p: &ResolverParams) {
    p.validate().expect("parsed resolver parameters validate");
    let _ = Resolver::new(&tomm().config.model, p.clone());
    build_with(|c| c.resolver = p.clone());
}

fn check_tasks(p: &TaskParams) {
    p.validate().expect("parsed task parameters validate");
    build_with(|c| c.tasks = p.clone());
}

fn check_setup(s: &ControllerSetup) {
    build_with(|c| {
        // As `ControllerConfig::load` does; the files it names stay the shipped ones.
        c.supervisor.policy = s.policy.unwrap_or(c.supervisor.policy);
        c.setup = s.clone();
    });
}

/// The property check of the `config_yaml` target.
pub fn check(data: &[u8]) {
    let text = text(data);
    if let Ok(p) = SkinParams::from_yaml_str(&text, SOURCE) {
        check_skin_params(&p);
    }
    if let Ok(l) = SkinLayout::from_yaml_str(&text, SOURCE) {
        check_layout(&l);
    }
    if let Ok(p) = SupervisorParams::from_yaml_str(&text, SOURCE) {
        check_supervisor(&p);
    }
    if let Ok(p) = ResolverParams::from_yaml_str(&text, SOURCE) {
        check_resolver(&p);
    }
    if let Ok(p) = TaskParams::from_yaml_str(&text, SOURCE) {
        check_tasks(&p);
    }
    if let Ok(s) = yaml::parse_str::<ControllerSetup>(&text, SOURCE) {
        check_setup(&s);
    }
}
