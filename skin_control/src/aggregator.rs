//! The skin aggregator's work, without the node around it: cells in, patch wrenches and markers
//! out (interactive-force-control paper eq. 6-8 through `skin_core::skin::aggregate`).
use r2r::builtin_interfaces::msg::Time;
use r2r::skin_msgs::msg::PatchWrenchArray;
use r2r::visualization_msgs::msg::MarkerArray;
use skin_core::skin::aggregate::{aggregate_patches, FusionParams, PatchWrench};
use skin_core::skin::layout::ResolvedLayout;

use crate::convert::cdr_cells::CdrCells;
use crate::convert::{update_cells, write_patch_array, CellBuffer, CellMessage, Issue, IssueCounts};
use crate::markers::SkinMarkers;

/// Cells to patch wrenches and markers for one layout; every buffer is kept between messages.
#[derive(Debug, Clone)]
pub struct Aggregator {
    layout: ResolvedLayout,
    cells: CellBuffer,
    wrenches: Vec<PatchWrench>,
    markers: SkinMarkers,
    patches_msg: PatchWrenchArray,
    markers_msg: MarkerArray,
    cdr: CdrCells,
    /// Stamp of the last cells read.
    stamp: Time,
    refused: u64,
}

impl Aggregator {
    /// An aggregator for `layout`, every cell reading zero.
    pub fn new(layout: ResolvedLayout) -> Self {
        Aggregator {
            cells: CellBuffer::new(&layout),
            markers: SkinMarkers::new(&layout),
            wrenches: Vec::with_capacity(layout.patches().len()),
            layout,
            patches_msg: PatchWrenchArray::default(),
            markers_msg: MarkerArray::default(),
            cdr: CdrCells::default(),
            stamp: Time::default(),
            refused: 0,
        }
    }

    /// The layout.
    pub fn layout(&self) -> &ResolvedLayout {
        &self.layout
    }

    /// Bad input counted since the start.
    pub fn issues(&self) -> &IssueCounts {
        self.cells.issues()
    }

    /// Messages refused whole since the start (bytes that are no `SkinCellArray`, arrays that
    /// disagree).
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// Takes one `/skin/cells` message as its serialized bytes (`Node::subscribe_raw`, read by
    /// [`CdrCells`]; issues go to `report`) and returns the `/skin/patches` message (every patch,
    /// stamped like the cells) and the `/skin/markers` update (empty when RViz is already up to
    /// date). Bytes that are no `SkinCellArray` and arrays that disagree are refused (the reason)
    /// and counted; the cells keep their readings.
    pub fn process(
        &mut self,
        data: &[u8],
        fusion: &FusionParams,
        report: impl FnMut(&Issue),
    ) -> Result<(&PatchWrenchArray, &MarkerArray), String> {
        let cdr = &mut self.cdr;
        let read = cdr.parse(data).and_then(|()| update_cells(&mut self.cells, &self.layout, cdr, report));
        if let Err(e) = read {
            self.refused += 1;
            return Err(e);
        }
        self.stamp = self.cdr.stamp();
        Ok(self.aggregate(fusion))
    }

    fn aggregate(&mut self, fusion: &FusionParams) -> (&PatchWrenchArray, &MarkerArray) {
        let readings = self.cells.readings();
        aggregate_patches(&self.layout, readings, fusion, &mut self.wrenches)
            .expect("the cell buffer has one reading per layout cell");
        let stamp = &self.stamp;
        write_patch_array(&self.layout, &self.wrenches, stamp, &mut self.patches_msg);
        self.markers.update(&self.layout, readings, fusion, &self.wrenches, stamp, &mut self.markers_msg);
        (&self.patches_msg, &self.markers_msg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use r2r::skin_msgs::msg::SkinCellArray;
    use r2r::WrappedTypesupport;
    use skin_core::model::RobotModel;
    use skin_core::skin::layout::SkinLayout;
    use skin_core::skin::params::SkinParams;
    use std::path::{Path, PathBuf};

    fn repo(rel: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
    }

    #[test]
    fn tomm_cells_to_patches() {
        let model = RobotModel::from_urdf_file(&repo("urdf/tomm.urdf")).unwrap();
        let layout = SkinLayout::load(&repo("config/skin/tomm.yaml")).unwrap().resolve(&model).unwrap();
        let fusion = SkinParams::load(&repo("config/skin_model.yaml")).unwrap().fusion;
        let first = layout.cells()[0].id;
        let mut agg = Aggregator::new(layout);
        let msg =
            SkinCellArray { cell_id: vec![first], force: vec![0.5; 3], proximity: vec![0.5], ..Default::default() };
        let bytes = |m: &SkinCellArray| m.to_serialized_bytes().unwrap();
        let (patches, markers) = agg.process(&bytes(&msg), &fusion, |i| panic!("{i}")).unwrap();
        assert_eq!(patches.patches.len(), 12);
        assert_eq!(patches.patches[0].active_cells, 1);
        assert_eq!(markers.markers.len(), 3);
        // cut bytes and disagreeing arrays are refused and counted; good bytes read on after them
        let good = bytes(&msg);
        assert!(agg.process(&good[..good.len() - 2], &fusion, |i| panic!("{i}")).unwrap_err().contains("ends inside"));
        let short = SkinCellArray { force: vec![0.5; 2], ..msg.clone() };
        let e = agg.process(&bytes(&short), &fusion, |i| panic!("{i}")).unwrap_err();
        assert!(e.starts_with("force has 2 values for 1 cells"), "{e}");
        assert_eq!(agg.refused(), 2);
        let again = agg.process(&good, &fusion, |i| panic!("{i}")).unwrap().0;
        assert_eq!(again.patches[0].active_cells, 1);
        assert_eq!(agg.issues().total(), 0);
    }
}
