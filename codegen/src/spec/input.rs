//! The limits on what a spec may ask of the generator, checked before anything is lowered,
//! and the spec text read from bytes.

use super::ir;
use crate::diag::{Diagnostic, Diagnostics};

/// The largest spec file read, in bytes (16 MiB). Larger input is refused before parsing.
pub const MAX_SOURCE_BYTES: usize = 16 << 20;

/// The most `[[body]]` or `[[joint]]` entries (URDF: `<link>` or `<joint>` elements) in one
/// spec. Fixed joints and their bodies count too, although they are merged.
pub const MAX_ENTRIES: usize = 1024;

/// The most degrees of freedom of a generated module: the movable one-DOF joints after
/// universal (2) and spherical (3) joints are expanded. The generated code grows with the cube
/// of the DOF (the dense `LᵀDL` of a chain's mass matrix) and generation time faster still
/// (a generic 16-joint chain takes 3 s, 32 joints 17 s, 64 joints about 3 min in the test
/// profile; branched trees are much cheaper: the 55-joint Romeo and the 101-joint TIAGo dual
/// URDFs take 2.5 s and 4.2 s in release), so larger specs are refused up front; one path
/// from the base is held to [`MAX_PATH_DOF`].
pub const MAX_DOF: usize = 128;

/// The most joint coordinates on one path from the base (`"base"`) to a body, counted as for
/// [`MAX_DOF`], along each body's first joint in (a closed loop's or parallel mechanism's
/// spanning tree). A chain's mass matrix is dense, and the code of its `LᵀDL` and of the
/// functions built on it grows with the cube of the path: a generic 32-joint chain is 24 MB
/// of Rust (7 s and 1.1 GB to generate in release), 64 joints 126 MB (55 s, 5.9 GB). Published
/// robots stay far below it (the longest path of the example-robot-data URDFs is 15: TIAGo), and
/// branched ones are cheap up to [`MAX_DOF`] (the 101-joint TIAGo dual: 4.2 s).
pub const MAX_PATH_DOF: usize = 32;

/// The longest name (of a mechanism, body, joint or spring; URDF: robot, link or joint), in
/// characters. Names become Rust identifiers and strings in the generated code.
pub const MAX_NAME_LEN: usize = 128;

/// The error of a name longer than [`MAX_NAME_LEN`], or `None`.
pub(crate) fn name_too_long(name: &str) -> Option<Diagnostic> {
    let n = name.chars().count();
    (n > MAX_NAME_LEN).then(|| {
        Diagnostic::error(format!(
            "name too long: {n} characters (the limit is {MAX_NAME_LEN})"
        ))
        .with_hint("names become Rust identifiers in the generated code; shorten it")
    })
}

/// The largest magnitude of any number in a spec (SI units). Larger values would overflow in
/// the generator's constant folding; nothing physical comes close.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// The value-range rule of every number read from a spec: finite is checked separately; this
/// is `|x| <= MAX_MAGNITUDE`.
pub(crate) fn in_range(x: f64) -> bool {
    x.abs() <= MAX_MAGNITUDE
}

/// The largest snapping tolerance (`[scene] snap`, `--snap`, [`super::SceneOverrides::snap`]): 0.01
/// (rad, m, or a rotation entry).
pub const MAX_SNAP: f64 = 1e-2;

/// `true` when `tol` is a snapping tolerance: in (0, [`MAX_SNAP`]] (NaN is not).
pub fn is_snap_tolerance(tol: f64) -> bool {
    tol > 0.0 && tol <= MAX_SNAP
}

/// The hint of a snapping tolerance out of range.
pub(crate) const SNAP_HINT: &str = "angles within this many rad of a multiple of π/2, rotation entries within it of 0 or ±1 and offsets within it (m) of 0 are taken as exact; e.g. 1e-6";

/// The text of a spec file read as bytes. A file that is not UTF-8 (UTF-16, Latin-1, cut
/// inside a character) is an invalid spec: the error points at the first invalid byte.
pub fn source_text(file_name: &str, bytes: Vec<u8>) -> Result<String, Diagnostics> {
    if bytes.len() > MAX_SOURCE_BYTES {
        // Checked first: the bytes may end inside a character.
        let mut d = Diagnostics::new(file_name, "");
        d.push(too_large(bytes.len(), false));
        return Err(d);
    }
    let e = match String::from_utf8(bytes) {
        Ok(s) => return Ok(s),
        Err(e) => e,
    };
    let at = e.utf8_error().valid_up_to();
    let bytes = e.as_bytes();
    let hint = if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        "the file looks like UTF-16 (it starts with a byte-order mark): save it as UTF-8"
    } else if e.utf8_error().error_len().is_none() {
        "the file ends inside a character: is it cut short?"
    } else {
        "save the file as UTF-8 (this byte looks like another encoding, such as Latin-1)"
    };
    // Shown with the invalid bytes replaced by U+FFFD: the text before them is unchanged.
    let shown = String::from_utf8_lossy(bytes);
    let mut d = Diagnostics::new(file_name, &shown);
    d.push(
        Diagnostic::error(format!(
            "the spec is not UTF-8 text: invalid byte 0x{:02X}",
            bytes[at]
        ))
        .with_span(at..at + '\u{fffd}'.len_utf8())
        .with_hint(hint),
    );
    Err(d)
}

/// The error of a spec over [`MAX_SOURCE_BYTES`]: `len` bytes, or at least that many when the
/// file was not read to its end (`whole` false).
pub(super) fn too_large(len: usize, whole: bool) -> Diagnostic {
    let size = if whole {
        format!("{len} bytes")
    } else {
        format!("more than {MAX_SOURCE_BYTES} bytes")
    };
    Diagnostic::error(format!("the spec is too large: {size} (the limit is {MAX_SOURCE_BYTES})"))
        .with_span(0..0)
        .with_hint(format!("nocdyn generates mechanisms of at most {MAX_DOF} degrees of freedom and {MAX_ENTRIES} bodies or joints; is this the right file?"))
}

/// The size limits ([`MAX_ENTRIES`], [`MAX_DOF`]), checked before lowering so that no stage
/// runs out of time or memory on a huge spec. `false` (after an error) when a limit is broken.
pub(super) fn check_size(spec: &ir::Spec, diags: &mut Diagnostics) -> bool {
    let anchor = spec.anchor.clone().unwrap_or(0..0);
    let mut ok = true;
    for (what, n, first) in [
        (
            "bodies",
            spec.bodies.len(),
            spec.bodies.get(MAX_ENTRIES).and_then(|b| b.span.clone()),
        ),
        (
            "joints",
            spec.joints.len(),
            spec.joints.get(MAX_ENTRIES).and_then(|j| j.span.clone()),
        ),
    ] {
        if n > MAX_ENTRIES {
            ok = false;
            diags.push(
                Diagnostic::error(format!(
                    "the spec is too large: {n} {what} (the limit is {MAX_ENTRIES})"
                ))
                .with_span(first.unwrap_or(anchor.clone()))
                .with_hint(format!("this is the first entry over the limit; nocdyn generates mechanisms of at most {MAX_ENTRIES} bodies and joints and {MAX_DOF} degrees of freedom")),
            );
        }
    }
    if !ok {
        return false;
    }
    let mut dof = 0;
    for j in &spec.joints {
        dof += j.kind.coordinates();
        if dof > MAX_DOF {
            diags.push(
                Diagnostic::error(format!(
                    "the mechanism has too many joint coordinates: more than {MAX_DOF} with joint \"{}\"",
                    j.name
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone().unwrap_or(anchor))
                .with_hint(format!("the generated code grows with the cube of the number of coordinates; nocdyn generates at most {MAX_DOF} (revolute and prismatic joints count 1, universal 2, spherical 3, fixed 0; for a parallel mechanism every leg joint counts)")),
            );
            return false;
        }
    }
    check_path(spec, anchor, diags)
}

/// [`MAX_PATH_DOF`]: the first joint (in the spec's order) whose path from the base has more
/// coordinates is an error. Each body is reached through the first joint naming it as child;
/// a walk stops at the base, at an unknown parent, or where it meets itself (a cycle, which the
/// topology checks report).
fn check_path(spec: &ir::Spec, anchor: std::ops::Range<usize>, diags: &mut Diagnostics) -> bool {
    let mut into: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for (k, j) in spec.joints.iter().enumerate() {
        into.entry(j.child.as_str()).or_insert(k);
    }
    // Coordinates from the base to each joint's child, memoized; `None` while unknown.
    let mut depth: Vec<Option<usize>> = vec![None; spec.joints.len()];
    // The walk that last went through each joint.
    let mut walked: Vec<usize> = vec![usize::MAX; spec.joints.len()];
    for k in 0..spec.joints.len() {
        let mut path = vec![k];
        walked[k] = k;
        let mut at = k;
        while let Some(&up) = into.get(spec.joints[at].parent.as_str()) {
            if depth[up].is_some() || walked[up] == k {
                break;
            }
            walked[up] = k;
            path.push(up);
            at = up;
        }
        let mut d = into
            .get(spec.joints[at].parent.as_str())
            .and_then(|&up| depth[up])
            .unwrap_or(0);
        for &j in path.iter().rev() {
            d += spec.joints[j].kind.coordinates();
            if depth[j].is_none() {
                depth[j] = Some(d);
            }
        }
        let j = &spec.joints[k];
        let n = depth[k].unwrap_or(0);
        if n > MAX_PATH_DOF {
            diags.push(
                Diagnostic::error(format!(
                    "the path from the base to joint \"{}\" has {n} joint coordinates (the limit is {MAX_PATH_DOF})",
                    j.name
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone().unwrap_or(anchor))
                .with_hint(format!("a chain's mass matrix is dense and its code grows with the cube of the path; nocdyn generates paths of at most {MAX_PATH_DOF} coordinates (revolute and prismatic joints count 1, universal 2, spherical 3, fixed 0). Published robots have at most about 15 on one path")),
            );
            return false;
        }
    }
    true
}
