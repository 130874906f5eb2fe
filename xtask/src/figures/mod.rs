//! `cargo xtask figures SET`: one module per figure set, each with a `draw_all(root, out)` that
//! draws its figures from the repository into a folder and returns the files written; [`plot`]
//! holds what they share (chart styling, polar axes, pictures drawn into a figure).

pub mod body;
pub mod dress;
pub mod fabric;
pub mod fit;
pub mod grid;
pub mod grid_body;
pub mod plot;
pub mod solver;
pub mod stability;
pub mod tradeoff;
pub mod tryon;
pub mod wet;
