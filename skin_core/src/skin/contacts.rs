//! The contacts of a link: its pressed cells grouped by neighbourhood, one group per thing that
//! presses it, each with its force `‖Σ F_i n_i‖`. A link pinched between two obstacles has two
//! contacts, and the force on it is their sum: the vector sum of all its cells reads contacts
//! from two sides low (`docs/supervisor.md`, "What the regulator does not bound").

use nalgebra::Vector3;

use super::resolved::ResolvedLayout;

/// Two cells of a link belong to one contact when they are at most this many times the link's
/// widest cell spacing apart (the largest distance from one of its cells to the nearest other).
const NEIGHBOUR_SPACINGS: f64 = 1.5;

/// One link's press this cycle \[N\].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinkForce {
    /// `Σ F_i` over its pressed cells: whether it is in contact at all.
    pub pressed_n: f64,
    /// The sum over its contacts of their `‖Σ F_i n_i‖`: the force on the link.
    pub contact_n: f64,
}

/// Groups a layout's pressed cells into contacts, per link; no allocation after [`Self::new`].
#[derive(Debug, Clone)]
pub struct LinkContacts {
    /// Per model frame: the distance within which two of its cells are neighbours \[m\].
    reach_m: Vec<f64>,
    /// Scratch: this cycle's pressed cells (layout index, force \[N\]).
    pressed: Vec<(usize, f64)>,
    /// Scratch: union-find parent per pressed cell.
    parent: Vec<usize>,
    /// Scratch: `Σ F_i n_i` of each contact, at its root.
    sums: Vec<Vector3<f64>>,
    /// Per model frame: the link's press.
    links: Vec<LinkForce>,
}

impl LinkContacts {
    /// The grouping for `layout` on a model with `nframes` frames.
    pub fn new(layout: &ResolvedLayout, nframes: usize) -> Self {
        let cells = layout.cells();
        let mut reach_m = vec![0.0_f64; nframes];
        for (i, a) in cells.iter().enumerate() {
            let nearest = (cells.iter().enumerate())
                .filter(|&(j, b)| j != i && b.frame == a.frame)
                .map(|(_, b)| (b.position_link - a.position_link).norm())
                .fold(f64::INFINITY, f64::min);
            if nearest.is_finite() {
                reach_m[a.frame] = reach_m[a.frame].max(NEIGHBOUR_SPACINGS * nearest);
            }
        }
        let n = cells.len();
        Self {
            reach_m,
            pressed: Vec::with_capacity(n),
            parent: Vec::with_capacity(n),
            sums: Vec::with_capacity(n),
            links: vec![LinkForce::default(); nframes],
        }
    }

    /// Groups the cells of `forces` (layout index, measured force \[N\]) pressed this cycle (force
    /// over 0) into contacts; returns per model frame the link's press: the sum of its cells'
    /// forces, and the sum over its contacts of their `‖Σ F_i n_i‖` (the norm of the link's
    /// vector sum when one thing presses it).
    pub fn update(&mut self, layout: &ResolvedLayout, forces: impl Iterator<Item = (usize, f64)>) -> &[LinkForce] {
        let cells = layout.cells();
        self.pressed.clear(); // within capacity: one per layout cell at most
        self.pressed.extend(forces.filter(|&(_, f)| f > 0.0));
        let k = self.pressed.len();
        self.parent.clear();
        self.parent.extend(0..k);
        for a in 0..k {
            for b in a + 1..k {
                let (ca, cb) = (&cells[self.pressed[a].0], &cells[self.pressed[b].0]);
                if ca.frame == cb.frame && (ca.position_link - cb.position_link).norm() <= self.reach_m[ca.frame] {
                    let (ra, rb) = (root(&mut self.parent, a), root(&mut self.parent, b));
                    self.parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        self.sums.clear();
        self.sums.resize(k, Vector3::zeros());
        self.links.fill(LinkForce::default());
        for a in 0..k {
            let (i, f) = self.pressed[a];
            let r = root(&mut self.parent, a);
            self.sums[r] += f * cells[i].normal_link;
            self.links[cells[i].frame].pressed_n += f;
        }
        for a in (0..k).filter(|&a| self.parent[a] == a) {
            self.links[cells[self.pressed[a].0].frame].contact_n += self.sums[a].norm();
        }
        &self.links
    }

    /// Per model frame: the link's press of the last [`Self::update`].
    pub fn links(&self) -> &[LinkForce] {
        &self.links
    }
}

/// The root of `a`'s group (halving the path on the way).
fn root(parent: &mut [usize], mut a: usize) -> usize {
    while parent[a] != a {
        parent[a] = parent[parent[a]];
        a = parent[a];
    }
    a
}
