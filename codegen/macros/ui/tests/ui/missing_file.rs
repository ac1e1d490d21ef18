// The spec does not exist: `cannot read …` at the literal.
mod arm {
    nocdyn_macros::mechanism!("tests/ui/no_such_spec.toml");
}

fn main() {}
