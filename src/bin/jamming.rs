//! Compressions to jamming at several rates (see `collide::lab::jamming`).
fn main() -> std::process::ExitCode {
    collide::lab::main_for(collide::lab::jamming::NAME, collide::lab::jamming::run)
}
