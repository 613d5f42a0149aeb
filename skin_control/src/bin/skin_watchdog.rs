//! `skin_watchdog`: zero commands when the task controller stops. Wiring in `skin_control::nodes::skin_watchdog`, work in
//! `skin_control::watchdog`.
fn main() -> anyhow::Result<()> {
    skin_control::nodes::skin_watchdog::main()
}
