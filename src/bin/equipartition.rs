//! Equipartition in a binary mixture (see `collide::lab::equipartition`).
fn main() -> std::process::ExitCode {
    collide::lab::main_for(collide::lab::equipartition::NAME, collide::lab::equipartition::run)
}
