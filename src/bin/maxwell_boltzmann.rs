//! Relaxation to the Maxwell–Boltzmann distribution (see `collide::lab::maxwell_boltzmann`).
fn main() -> std::process::ExitCode {
    collide::lab::main_for(collide::lab::maxwell_boltzmann::NAME, collide::lab::maxwell_boltzmann::run)
}
