//! The equation of state of hard disks or spheres (see `collide::lab::equation_of_state`).
fn main() -> std::process::ExitCode {
    collide::lab::main_for(collide::lab::equation_of_state::NAME, collide::lab::equation_of_state::run)
}
