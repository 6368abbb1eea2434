//! The hard-disk equation of state (see `collide::lab::equation_of_state`).
fn main() -> std::process::ExitCode {
    collide::lab::main_for(collide::lab::equation_of_state::NAME, collide::lab::equation_of_state::run)
}
