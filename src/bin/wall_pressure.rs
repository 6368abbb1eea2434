//! Pressure on hard walls (see `collide::lab::wall_pressure`).
fn main() -> std::process::ExitCode {
    collide::lab::main_for(collide::lab::wall_pressure::NAME, collide::lab::wall_pressure::run)
}
