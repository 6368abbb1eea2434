//! Collision frequency against Enskog (see `collide::lab::collision_rate`).
fn main() -> std::process::ExitCode {
    collide::lab::main_for(collide::lab::collision_rate::NAME, collide::lab::collision_rate::run)
}
