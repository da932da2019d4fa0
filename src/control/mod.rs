//! Control code shared by the simulated and the real cell.
