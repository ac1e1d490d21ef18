// A TOML syntax error: a missing comma in an array.
mod arm {
    nocdyn_macros::mechanism!("tests/ui/syntax_error.toml");
}

fn main() {}
