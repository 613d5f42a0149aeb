//! This cycle's press on the robot: every live cell's measured force (intentional-contact paper
//! eq. 6) and each link's contacts ([`LinkContacts`]), measured once per cycle for the
//! supervisor's `‖F_c‖` and the skin's approach bound.

use crate::skin::aggregate::FusionParams;
use crate::skin::characteristic::PreparedForce;
use crate::skin::contacts::{LinkContacts, LinkForce};
use crate::skin::layout::ResolvedLayout;
use crate::skin::live::LiveCells;

/// The measured forces of one cycle's live cells and the force on each link.
#[derive(Debug, Clone)]
pub(crate) struct Press {
    force: PreparedForce,
    /// Per live cell, in [`LiveCells::cells`] order: its measured force \[N\] (0 below the threshold).
    forces_n: Vec<f64>,
    contacts: LinkContacts,
}

impl Press {
    /// Room for every cell of `layout` on a model with `nframes` frames; forces read through `force`.
    pub(crate) fn new(force: PreparedForce, layout: &ResolvedLayout, nframes: usize) -> Self {
        Self { force, forces_n: Vec::with_capacity(layout.num_cells()), contacts: LinkContacts::new(layout, nframes) }
    }

    /// Measures the live `cells` and groups the pressed ones into their links' contacts.
    pub(crate) fn update(&mut self, layout: &ResolvedLayout, cells: &LiveCells, fusion: &FusionParams) {
        self.forces_n.clear(); // within capacity: one per layout cell at most
        for (_, reading) in cells.cells() {
            self.forces_n.push(fusion.cell_force_n(reading, &self.force).unwrap_or(0.0));
        }
        let ids = cells.cells().iter().map(|(i, _)| *i);
        self.contacts.update(layout, ids.zip(self.forces_n.iter().copied()));
    }

    /// The live cells' measured forces \[N\], in [`LiveCells::cells`] order.
    pub(crate) fn cell_forces_n(&self) -> &[f64] {
        &self.forces_n
    }

    /// Per model frame: the link's press.
    pub(crate) fn links(&self) -> &[LinkForce] {
        self.contacts.links()
    }

    /// The supervisor's `‖F_c‖` (intentional-contact paper Table I): the largest force on one
    /// link, the sum over its contacts of their `‖Σ F_i n_i‖` \[N\]. A link pinched between two
    /// obstacles carries both; the vector sum of its cells reads them low, down to nothing for a
    /// squeeze from opposite sides (`docs/supervisor.md`).
    pub(crate) fn largest_link_n(&self) -> f64 {
        self.links().iter().map(|l| l.contact_n).fold(0.0, f64::max)
    }
}
