//! How the cost of `Controller::update` grows (`docs/performance.md`), on TOMM's setup of
//! `controller_update_tomm` (four levels plus posture, 360-point scan):
//!
//! - `controller_update_tomm_cells_<n>`: TOMM's skin regenerated at a finer pitch to about n
//!   cells (700, 2 000, 5 000, 10 000) with the same 36 live cells (12 in range over the whole
//!   skin, 24 touches on the right forearm and palm): the cost of the number of cells.
//! - `controller_update_tomm_range_<k>` and `controller_update_tomm_contact_<k>`: the shipped
//!   718-cell skin with k cells in range of an obstacle (avoidance rows) or in contact (patch
//!   wrenches), spread evenly over the skin, k from 0 to all: the cost of active cells.
//!
//! The joints' series is `controller_update_{planar7,tomm,humanoid}` (benches/controller.rs).

mod support;

use criterion::{criterion_group, criterion_main, Criterion};
use skin_core::controller::Controller;
use skin_core::model::RobotModel;
use skin_core::skin::generate::{generate_layout, GeneratorSpec, LinkSelection, PatchFrame};
use skin_core::skin::layout::ResolvedLayout;
use support::{bench, readings, scan, selected, tomm_config, Point};

/// Cell counts of the cells' series.
const CELLS: [usize; 4] = [700, 2000, 5000, 10000];
/// Active cells of the active cells' series (up to 718, two thirds of the shipped layout).
const ACTIVE: [usize; 8] = [0, 25, 50, 100, 200, 350, 500, 718];

/// TOMM's shipped layout regenerated at `pitch_m` (the `skin_layout` command of
/// `config/skin/tomm.yaml`'s header with another pitch).
fn tomm_layout(model: &RobotModel, pitch_m: f64) -> ResolvedLayout {
    let mut links = Vec::new();
    for side in ["left", "right"] {
        for link in ["upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link", "palm"] {
            links.push(format!("{side}_{link}").parse::<LinkSelection>().unwrap());
        }
    }
    let spec = GeneratorSpec {
        links,
        pitch_m,
        spheres: true,
        caps: true,
        patch_frame: PatchFrame::Primitive,
        ..Default::default()
    };
    generate_layout(model, &spec).unwrap().resolve(model).unwrap()
}

/// TOMM's layout with about `cells` cells: the pitch found by bisection (within 3 %).
fn tomm_layout_with(model: &RobotModel, cells: usize) -> ResolvedLayout {
    let (mut lo, mut hi) = (0.002, 0.06); // pitch: many cells at lo, few at hi
    loop {
        let pitch = 0.5 * (lo + hi);
        let layout = tomm_layout(model, pitch);
        let n = layout.num_cells();
        if n.abs_diff(cells) * 100 <= 3 * cells || hi - lo < 1e-6 {
            return layout;
        }
        if n > cells {
            lo = pitch;
        } else {
            hi = pitch;
        }
    }
}

fn cells(c: &mut Criterion) {
    for n in CELLS {
        let id = format!("controller_update_tomm_cells_{n}");
        if !selected(&id) {
            continue; // the layout's bisection is the slow part of the setup
        }
        let mut cfg = tomm_config();
        cfg.layout = tomm_layout_with(&cfg.model, n);
        let cells = readings(&cfg.layout, 12, 24, &[8, 12]);
        let ctl = Controller::new(cfg, 0.0).unwrap();
        bench(c, Point::new(id, ctl, cells, scan()));
    }
}

fn active(c: &mut Criterion) {
    for series in ["range", "contact"] {
        for k in ACTIVE {
            let cfg = tomm_config();
            let k = k.min(cfg.layout.num_cells());
            let all: Vec<u32> = cfg.layout.patches().iter().map(|p| p.id).collect();
            let cells = match series {
                "range" => readings(&cfg.layout, k, 0, &[]),
                _ => readings(&cfg.layout, 0, k, &all),
            };
            let ctl = Controller::new(cfg, 0.0).unwrap();
            bench(c, Point::new(format!("controller_update_tomm_{series}_{k}"), ctl, cells, scan()));
        }
    }
}

criterion_group!(benches, cells, active);
criterion_main!(benches);
