// The bundled parallel and closed-loop specs by module name (`mechanisms/specs/<name>.toml`):
// included by the build script, which generates their variants, and by the library
// (`pkm::PARALLEL`, `closed::CLOSED`), whose tests walk them.

/// The bundled parallel specs (module names).
pub const PARALLEL: [&str; 10] = [
    "gough_stewart",
    "sliding_hexapod",
    "rus_hexapod",
    "agile_eye",
    "planar_five_bar",
    "delta_rl5",
    "planar_3rrr",
    "tsai_3upu",
    "prs_head",
    "delta4_rl5",
];

/// The bundled closed-loop specs (module names).
pub const CLOSED: [&str; 7] = [
    "four_bar",
    "five_bar_joints",
    "spherical_five_bar",
    "bricard",
    "n_four_bar",
    "tripod_3prs",
    "andrews_squeezer",
];
