// A validation error: a negative mass.
mod arm {
    nocdyn_macros::mechanism!("tests/ui/negative_mass.toml");
}

fn main() {}
