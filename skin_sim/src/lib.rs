//! `skin_sim`: MuJoCo worlds for skin_control, built from our URDFs and scene files.
#![warn(missing_docs)]
