//! `skin_aggregator`: skin cells in, patch wrenches and RViz markers out (interactive-force-control paper eq. 6-8). Wiring in `skin_control::nodes::skin_aggregator`, work in
//! `skin_control::aggregator`.
fn main() -> anyhow::Result<()> {
    skin_control::nodes::skin_aggregator::main()
}
