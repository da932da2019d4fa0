//! The UR5e's flange at its home pose, and the joints that lower it 10 cm:
//! `cargo run -p tendril-ur5e --example reach`.

use tendril_ur5e::pose::pose_vector;
use tendril_ur5e::{HOME, forward, inverse_near};

fn main() {
    let home = forward(&HOME);
    println!("home: joints {:.3?} rad, flange {:.4?} (m, rotation vector)", HOME, pose_vector(&home));
    let mut lower = home;
    lower.translation.vector.z -= 0.1;
    match inverse_near(&lower, &HOME) {
        Some(q) => println!("10 cm lower: joints {q:.3?} rad"),
        None => println!("10 cm lower: out of reach"),
    }
}
