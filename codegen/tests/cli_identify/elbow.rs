//! A Delta's elbow crosses (`cross` on a `[[parallelogram]]`, docs/spec.md, "Parallelograms"):
//! the truth of `out.rs`'s `delta_out_writes_the_elbow_crosses`.

/// The bundled Delta with an elbow cross on every parallelogram (0.14–0.18 kg, its mass
/// centre off the elbow, a full inertia), different per copy.
pub(super) fn with_elbow_crosses(nominal: &str) -> String {
    let out = nominal.replace(
        "name = \"forearm{i}\"\n",
        "name = \"forearm{i}\"\ncross = { mass = \"0.12 + 0.02 * i\", com = [0.004, \"0.01 * i - 0.02\", -0.006], inertia = { ixx = 3e-4, iyy = \"1e-4 + 2e-5 * i\", izz = 2.5e-4, ixz = 1e-5, ixy = -2e-5 } }\n",
    );
    assert_ne!(out, nominal);
    out
}
