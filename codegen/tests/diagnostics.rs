//! Rendered diagnostics of every bad spec in `tests/data/bad/` (one file per kind of error), of
//! every bad parallel spec in `tests/data/bad_parallel/` (read with `load_mechanism`) and of the
//! accepted-with-warnings specs in `tests/data/warn/`, as insta snapshots (the list of kinds is
//! `tests/data/README.md`); specs too large to generate; and the good specs (including every complete example in `docs/spec.md` and
//! the bundled parallel specs in `mechanisms/specs/`) load without warnings.

use std::path::Path;

use codegen::spec::Mechanism;

/// Loads `path` under its bare file name (no absolute paths in snapshots) and renders the
/// diagnostics; a bad spec must fail.
fn render_bad(path: &Path) -> String {
    let name = path.file_name().unwrap().to_str().unwrap();
    let source = std::fs::read_to_string(path).unwrap();
    match codegen::spec::load_tree(name, &source) {
        Ok((model, warnings)) => panic!(
            "{name} was accepted ({} joints), warnings:\n{}",
            model.dof(),
            warnings.render()
        ),
        Err(diags) => {
            assert!(diags.has_errors());
            for d in diags.iter() {
                assert!(d.span.is_some(), "{name}: diagnostic without a span: {d:?}");
            }
            diags.render()
        }
    }
}

#[test]
fn bad_toml_specs() {
    insta::glob!("data/bad", "*.toml", |path| {
        insta::assert_snapshot!(render_bad(path));
    });
}

#[cfg(feature = "urdf")]
#[test]
fn bad_urdf_specs() {
    insta::glob!("data/bad", "*.urdf", |path| {
        insta::assert_snapshot!(render_bad(path));
    });
}

/// XML that is not a URDF (MJCF, SDF, anything else) is named for what it is, at its root
/// element, instead of failing as TOML.
#[test]
fn other_xml_formats() {
    insta::glob!("data/bad", "*.xml", |path| {
        insta::assert_snapshot!(render_bad(path));
    });
}

/// A URDF is recognized by its `<robot>` root whatever the file is called.
#[cfg(feature = "urdf")]
#[test]
fn a_urdf_under_another_name_is_read() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/puma560.urdf");
    let source = std::fs::read_to_string(path).unwrap();
    let (as_urdf, _) = codegen::spec::load_tree("puma560.urdf", &source).unwrap();
    let (as_xml, _) = codegen::spec::load_tree("puma560.xml", &source)
        .unwrap_or_else(|e| panic!("{}", e.render()));
    assert_eq!(as_urdf, as_xml);
}

/// Loads `path`, which must be accepted with at least one warning, and renders the warnings.
fn render_warnings(path: &Path) -> String {
    let name = path.file_name().unwrap().to_str().unwrap();
    let source = std::fs::read_to_string(path).unwrap();
    match codegen::spec::load_tree(name, &source) {
        Ok((_, warnings)) => {
            assert!(!warnings.is_empty(), "{name}: no warning");
            for d in warnings.iter() {
                assert!(!d.is_error() && d.span.is_some(), "{name}: {d:?}");
            }
            warnings.render()
        }
        Err(e) => panic!("{name} was rejected:\n{}", e.render()),
    }
}

/// Specs that are accepted with warnings (`tests/data/warn/`): non-unit axes are normalized.
#[test]
fn warning_specs() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/warn");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| cfg!(feature = "urdf") || p.extension().is_none_or(|e| e != "urdf"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    for path in files {
        let name = path.file_name().unwrap().to_str().unwrap().to_owned();
        insta::assert_snapshot!(format!("warning_specs@{name}"), render_warnings(&path));
    }
}

/// A serial chain of `n` revolute joints, as TOML.
fn chain_toml(n: usize) -> String {
    tree_toml(1, n)
}

/// `branches` serial chains of `n` revolute joints each from the base, as TOML.
fn tree_toml(branches: usize, n: usize) -> String {
    let mut s = String::from("[mechanism]\nname = \"huge\"\n");
    for b in 0..branches {
        // The first branch's names are a chain's: `l{i}`, `j{i}`.
        let tag = if b == 0 {
            String::new()
        } else {
            format!("b{b}_")
        };
        for i in 0..n {
            let parent = if i == 0 {
                "base".to_owned()
            } else {
                format!("{tag}l{}", i - 1)
            };
            s += &format!(
                "[[body]]\nname = \"{tag}l{i}\"\nmass = 1.0\ncom = [0.1, 0.0, 0.0]\n[[joint]]\nname = \"{tag}j{i}\"\nkind = \"R\"\nparent = \"{parent}\"\nchild = \"{tag}l{i}\"\norigin = {{ xyz = [0.2, 0.0, 0.0] }}\naxis = [0.0, 1.0, 0.0]\n"
            );
        }
    }
    s
}

/// Specs too large to generate are refused before lowering, quickly and with a clear message:
/// too many coordinates, too many on one path from the base, too many entries (TOML and URDF)
/// and too many bytes. `compile` on them returns the same diagnostics (it never starts
/// generating).
#[test]
fn specs_too_large_are_refused_up_front() {
    use codegen::spec::{MAX_DOF, MAX_ENTRIES, MAX_PATH_DOF, MAX_SOURCE_BYTES};
    let start = std::time::Instant::now();
    let check = |name: &str, src: &str, expect: &str| -> String {
        let e = codegen::spec::load_mechanism(name, src).unwrap_err();
        let r = e.render();
        assert!(r.contains(expect), "{name}:\n{r}");
        let c = codegen::compile(name, src, &codegen::Config::default()).unwrap_err();
        assert_eq!(c.render(), r);
        r
    };
    // Exactly at the limits is fine (only loaded here: generating takes a while): branches of
    // `MAX_PATH_DOF` joints up to `MAX_DOF` in all.
    assert_eq!(MAX_DOF % MAX_PATH_DOF, 0);
    codegen::spec::load_tree(
        "at_limit.toml",
        &tree_toml(MAX_DOF / MAX_PATH_DOF, MAX_PATH_DOF),
    )
    .unwrap();
    // One joint more on one path: a 33-joint chain (7 s, 1.1 GB and 24 MB of code in release at
    // 32 joints; 64 joints took 55 s and 5.9 GB), refused at its last joint.
    let path = check(
        "long_path.toml",
        &tree_toml(2, MAX_PATH_DOF + 1),
        &format!(
            "the path from the base to joint \"j{MAX_PATH_DOF}\" has {} joint coordinates (the limit is {MAX_PATH_DOF})",
            MAX_PATH_DOF + 1
        ),
    );
    assert!(path.contains("long_path.toml:"), "{path}");
    let dof = check(
        "too_many_dof.toml",
        &chain_toml(MAX_DOF + 1),
        "too many joint coordinates",
    );
    insta::assert_snapshot!("too_many_dof_generated", dof);
    let entries = check(
        "huge.toml",
        &chain_toml(20 * MAX_ENTRIES),
        "the spec is too large: 20480 bodies",
    );
    assert!(entries.contains("20480 joints"), "{entries}");
    #[cfg(feature = "urdf")]
    {
        let mut u = String::from("<robot name=\"huge\">\n<link name=\"l0\"/>\n");
        for i in 1..=20 * MAX_ENTRIES {
            u += &format!(
                "<link name=\"l{i}\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>\n<joint name=\"j{i}\" type=\"revolute\"><parent link=\"l{}\"/><child link=\"l{i}\"/></joint>\n",
                i - 1
            );
        }
        u += "</robot>\n";
        check(
            "huge.urdf",
            &u,
            "the robot is too large: 20481 <link> elements",
        );
    }
    let big = format!("# {}\n", "x".repeat(MAX_SOURCE_BYTES));
    check("big.toml", &big, "the spec is too large");
    assert!(
        start.elapsed().as_secs() < 20,
        "refusing large specs took {:?}",
        start.elapsed()
    );
}

/// As [`render_bad`], through `load_mechanism` (trees and parallel mechanisms).
fn render_bad_mechanism(path: &Path) -> String {
    let name = path.file_name().unwrap().to_str().unwrap();
    let source = std::fs::read_to_string(path).unwrap();
    match codegen::spec::load_mechanism(name, &source) {
        Ok((m, warnings)) => panic!(
            "{name} was accepted ({}), warnings:\n{}",
            m.name(),
            warnings.render()
        ),
        Err(diags) => {
            assert!(diags.has_errors());
            for d in diags.iter() {
                assert!(d.span.is_some(), "{name}: diagnostic without a span: {d:?}");
            }
            diags.render()
        }
    }
}

#[test]
fn bad_parallel_specs() {
    insta::glob!("data/bad_parallel", "*.toml", |path| {
        insta::assert_snapshot!(render_bad_mechanism(path));
    });
}

fn load_clean_mechanism(name: &str, source: &str) -> Mechanism {
    match codegen::spec::load_mechanism(name, source) {
        Ok((m, warnings)) => {
            assert!(warnings.is_empty(), "{name}:\n{}", warnings.render());
            m
        }
        Err(e) => panic!("{name}:\n{}", e.render()),
    }
}

/// The bundled parallel specs and the good parallel test specs load as parallel mechanisms
/// whose `validate()` passes.
#[test]
fn good_parallel_specs_load_and_validate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut n = 0;
    for dir in [
        root.join("tests/data/good_parallel"),
        root.join("../mechanisms/specs"),
    ] {
        let mut entries: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        entries.sort();
        for path in entries {
            let name = path.file_name().unwrap().to_str().unwrap().to_owned();
            let source = std::fs::read_to_string(&path).unwrap();
            let Mechanism::Parallel(m) = load_clean_mechanism(&name, &source) else {
                // The bundled folder also holds trees.
                continue;
            };
            m.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            // `load` refuses it, pointing at the [platform] table.
            let e = codegen::spec::load_tree(&name, &source).unwrap_err();
            assert!(e.render().contains("parallel mechanism"), "{}", e.render());
            n += 1;
        }
    }
    assert!(n >= 5, "found {n} parallel specs");
}

fn load_clean(name: &str, source: &str) -> runtime::model::Model {
    match codegen::spec::load_tree(name, source) {
        Ok((model, warnings)) => {
            assert!(warnings.is_empty(), "{name}:\n{}", warnings.render());
            model
        }
        Err(e) => panic!("{name}:\n{}", e.render()),
    }
}

#[test]
fn good_specs_load_without_warnings() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/good");
    let mut n = 0;
    let mut entries: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        let name = path.file_name().unwrap().to_str().unwrap().to_owned();
        if name.ends_with(".urdf") && !cfg!(feature = "urdf") {
            continue;
        }
        let model = load_clean(&name, &std::fs::read_to_string(&path).unwrap());
        assert!(model.dof() > 0);
        n += 1;
    }
    assert!(n >= 1);
}

#[test]
fn puma560_example_lowers_as_documented() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/good");
    let src = std::fs::read_to_string(dir.join("puma560.toml")).unwrap();
    let m = load_clean("puma560.toml", &src);
    assert_eq!(m.name, "puma560");
    assert_eq!(m.dof(), 6);
    let names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["j1", "j2", "j3", "j4", "j5", "j6"]);
    // The tool flange (fixed) is merged into link6.
    assert_eq!(m.bodies.len(), 6);
    assert!((m.bodies[5].mass - (0.09 + 0.05)).abs() < 1e-15);
}

/// Every ```toml block of docs/spec.md that starts with `[mechanism]` is a complete, valid
/// spec (a tree, or a parallel mechanism whose `validate()` passes); there is at least one of
/// each.
#[test]
fn examples_in_docs_load_without_warnings() {
    let doc = include_str!("../../docs/spec.md");
    let mut n = 0;
    let mut parallel = 0;
    let mut rest = doc;
    while let Some(start) = rest.find("```toml\n") {
        let body = &rest[start + 8..];
        let end = body.find("```").unwrap();
        let block = &body[..end];
        if block.trim_start().starts_with("[mechanism]") {
            let name = format!("docs/spec.md example {n}");
            match load_clean_mechanism(&name, block) {
                Mechanism::Tree(_) => {
                    load_clean(&name, block);
                }
                Mechanism::Parallel(m) => {
                    m.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
                    parallel += 1;
                }
                Mechanism::Closed(m) => {
                    runtime::closed::Plan::new(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
                }
            }
            n += 1;
        }
        rest = &body[end + 3..];
    }
    assert!(n >= 2, "no complete example found in docs/spec.md");
    assert!(
        parallel >= 1,
        "no complete parallel example found in docs/spec.md"
    );
}

/// A loop that does not close at home is reported at its own loop-closing joint (not the
/// first one), and the `child_origin` its hint offers closes it. Andrews' squeezer has three
/// loop-closing joints; the third one is moved by 1 mm.
#[test]
fn an_open_loop_is_reported_at_its_joint_with_the_child_origin_that_closes_it() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../mechanisms/specs/andrews_squeezer.toml");
    let good = std::fs::read_to_string(path).unwrap();
    let (line, line_no) = good
        .lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with("child_origin"))
        .map(|(i, l)| (l, i + 1))
        .nth(2)
        .expect("three loop-closing joints");
    assert_eq!(line, "child_origin = { xyz = [0.0, -0.035, 0.0] }");
    let bad: String = good
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == line_no {
                "child_origin = { xyz = [0.0, -0.036, 0.0] }".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let e = match codegen::spec::load_mechanism("squeezer.toml", &bad) {
        Ok(_) => panic!("an open loop was accepted"),
        Err(e) => e.render(),
    };
    assert!(
        e.contains(&format!("squeezer.toml:{line_no}:")),
        "not at line {line_no}:\n{e}"
    );
    let fix = e
        .split("`child_origin = ")
        .nth(1)
        .and_then(|s| s.split("` closes").next())
        .unwrap_or_else(|| panic!("no child_origin in the hint:\n{e}"));
    let fixed: String = bad
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == line_no {
                format!("child_origin = {fix}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    if let Err(e) = codegen::spec::load_mechanism("squeezer.toml", &fixed) {
        panic!(
            "the offered child_origin {fix} does not close the loop:\n{}",
            e.render()
        );
    }
}

/// A frame that names no body and resembles none (here a URDF habit: the root link `world`)
/// gets a hint that says what can be named, `"base"` among it: the hint listed only bodies, so
/// a URDF user naming the root link (`base_link` of a Kinova Gen3) learnt no way to ask for the
/// fixed world's frame.
#[test]
fn an_unknown_frame_hint_names_base() {
    let source = r#"[mechanism]
name = "arm"

[[body]]
name = "link1"
mass = 1.0
inertia = { ixx = 0.01, iyy = 0.01, izz = 0.01 }

[[joint]]
name = "j1"
kind = "revolute"
parent = "base"
child = "link1"

[scene]
frames = ["world"]
"#;
    let diags = codegen::spec::load_tree("arm.toml", source).unwrap_err();
    let text = diags.render();
    assert!(text.contains("unknown frame \"world\""), "{text}");
    assert!(text.contains("arm.toml:16:"), "{text}");
    assert!(text.contains("or the fixed world: \"base\""), "{text}");
    let ok = source.replace("[\"world\"]", "[\"base\", \"link1\"]");
    codegen::spec::load_tree("arm.toml", &ok).unwrap_or_else(|d| panic!("{}", d.render()));
}

/// A `[[pattern]]` that cannot be expanded is the only error reported: with `copies = 65` the
/// legs were missing, and the whole-mechanism counts (no joint actuated, no joint into the
/// platform, the mobility) came first, ahead of it in the file. A mistake in a pattern's entry
/// found after expansion (a negative mass) is reported once, not once per copy at the same line.
#[test]
fn a_pattern_s_mistake_is_reported_once() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/gough_stewart.toml");
    let source = std::fs::read_to_string(&path).unwrap();
    let load = |text: &str| match codegen::spec::load_mechanism("gs.toml", text) {
        Ok(_) => panic!("accepted"),
        Err(d) => d,
    };
    let copies = source.replacen("copies = 6", "copies = 65", 1);
    assert_ne!(copies, source);
    let d = load(&copies);
    let messages: Vec<&str> = d.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(
        messages,
        ["copies must be a whole number from 1 to 64"],
        "{}",
        d.render()
    );
    let at = source.find("[[pattern.body]]").unwrap();
    let mass = at + source[at..].find("mass = ").unwrap();
    let end = mass + source[mass..].find('\n').unwrap();
    let negative = format!("{}mass = -1.0{}", &source[..mass], &source[end..]);
    let d = load(&negative);
    assert_eq!(d.error_count(), 1, "{}", d.render());
    let text = d.render();
    assert!(text.contains("negative mass -1"), "{text}");
    assert!(text.contains("and 5 more made from this text"), "{text}");
}

/// A joint's `<limit>`, `<safety_controller>` and `<calibration>` are read as docs/spec.md
/// ("URDF input") says: a `<limit>` that gives no usable range is no limit, and the other two
/// are ignored, however they are written. urdf-rs used to reject a `<limit>` without
/// `velocity` (valid in `<limit lower upper effort>` as many hand-written URDFs have it), a
/// `<safety_controller>` without `k_velocity` or a word in `effort` or `rising`, at the
/// `<robot>` tag as "URDF: custom: missing field `velocity`". A `<mimic>`'s numbers are still
/// checked, at their attribute.
#[cfg(feature = "urdf")]
#[test]
fn urdf_limit_safety_controller_and_calibration_never_fail_the_file() {
    let urdf = |extra: &str| {
        format!(
            r#"<?xml version="1.0"?>
<robot name="r">
<link name="a"/>
<link name="b"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="c"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="2"/><safety_controller soft_lower_limit="-1" soft_upper_limit="1"/></joint>
<joint name="k" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 1 0"/>
  {extra}
</joint>
</robot>
"#
        )
    };
    let overrides = codegen::spec::SceneOverrides::default();
    for (extra, k_limit) in [
        (
            r#"<limit lower="-1" upper="1" effort="10"/>"#,
            Some((-1.0, 1.0, None)),
        ),
        (
            r#"<limit lower="-2" upper="2" effort="x" velocity="1"/>"#,
            Some((-2.0, 2.0, Some(1.0))),
        ),
        (r#"<limit lower="nan" upper="inf" velocity="-1"/>"#, None),
        (r#"<limit lower="abc" upper="1" velocity="1"/>"#, None),
        (r#"<calibration rising="x"/>"#, None),
        (r#"<safety_controller k_position="fast"/>"#, None),
    ] {
        let loaded = codegen::spec::load("r.urdf", &urdf(extra), &overrides)
            .unwrap_or_else(|d| panic!("{extra}: {}", d.render()));
        let limit = |name: &str| {
            loaded
                .limits
                .iter()
                .find(|l| l.joint == name)
                .map(|l| (l.lower, l.upper, l.velocity))
        };
        assert_eq!(limit("j"), Some((-1.0, 1.0, Some(2.0))), "{extra}");
        assert_eq!(limit("k"), k_limit, "{extra}");
    }
    for (extra, key) in [
        (
            r#"<mimic joint="j" multiplier="two"/>"#,
            r#"joint "k".mimic.multiplier"#,
        ),
        (
            r#"<mimic joint="j" offset="nan"/>"#,
            r#"joint "k".mimic.offset"#,
        ),
        (r#"<mimic multiplier="2"/>"#, r#"joint "k".mimic"#),
    ] {
        let e = codegen::spec::load("r.urdf", &urdf(extra), &overrides)
            .err()
            .unwrap_or_else(|| panic!("{extra}: loaded"))
            .render();
        assert!(e.contains("r.urdf:9:"), "{extra}: {e}");
        assert!(e.contains(key), "{extra}: {e}");
        assert!(!e.contains("custom"), "{extra}: {e}");
    }
}

/// Two of an element a `<joint>`, `<link>` or `<inertial>` holds once, and an `<axis>` without
/// `xyz`, are errors at that element with its key; urdf-rs reported them at the `<robot>`
/// tag as "URDF: custom: duplicate field `axis`" or "missing field `xyz`".
#[cfg(feature = "urdf")]
#[test]
fn urdf_duplicate_elements_and_an_axis_without_xyz_are_located() {
    let urdf = |link_extra: &str, joint_extra: &str| {
        format!(
            r#"<?xml version="1.0"?>
<robot name="r">
<link name="a"/>
<link name="b"><inertial><mass value="1"/>{link_extra}<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="k" type="continuous"><parent link="a"/><child link="b"/>
  {joint_extra}
</joint>
</robot>
"#
        )
    };
    for (link_extra, joint_extra, line, key) in [
        ("", r#"<axis/>"#, 6, r#"joint "k".axis"#),
        (
            "",
            r#"<axis xyz="0 0 1"/><axis xyz="1 0 0"/>"#,
            6,
            r#"joint "k".axis"#,
        ),
        ("", r#"<parent link="a"/>"#, 6, r#"joint "k".parent"#),
        (
            "",
            r#"<origin xyz="0 0 1"/><origin xyz="0 0 2"/>"#,
            6,
            r#"joint "k".origin"#,
        ),
        (r#"<mass value="2"/>"#, "", 4, r#"link "b".inertial.mass"#),
    ] {
        let e = codegen::spec::load_tree("r.urdf", &urdf(link_extra, joint_extra))
            .err()
            .unwrap_or_else(|| panic!("{link_extra}{joint_extra}: loaded"))
            .render();
        assert!(e.contains(&format!("r.urdf:{line}:")), "{joint_extra}: {e}");
        assert!(e.contains(key), "{joint_extra}: {e}");
        assert!(!e.contains("custom"), "{joint_extra}: {e}");
    }
}

/// A `[scene]` payload's inertia that no rigid body has is a warning at the payload's
/// `inertia`, with the payload's own principal moments; the body it rides on is judged by its
/// own tensor. The check saw only the sum, and blamed the body's own (physical) `inertia`,
/// with the sum's moments. A negative payload mass is an error at the `mass`, not at `body`.
#[test]
fn a_payload_is_judged_at_its_own_place() {
    let spec = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/planar_2r.toml"),
    )
    .unwrap();
    let lines = spec.lines().count();
    let with = |payload: &str| format!("{spec}\n[scene]\npayload = {payload}\n");
    let overrides = codegen::spec::SceneOverrides::default();
    let src =
        with(r#"{ body = "link2", mass = 1.0, inertia = { ixx = -1.0, iyy = 1.0, izz = 1.0 } }"#);
    let loaded = codegen::spec::load("arm.toml", &src, &overrides)
        .unwrap_or_else(|d| panic!("{}", d.render()));
    let w = loaded.warnings.render();
    assert_eq!(w.matches("warning:").count(), 1, "{w}");
    assert!(
        w.contains("payload inertia is not positive semi-definite"),
        "{w}"
    );
    assert!(w.contains("scene.payload.inertia"), "{w}");
    assert!(w.contains(&format!("arm.toml:{}:", lines + 3)), "{w}");
    assert!(w.contains("principal moments -1, 1, 1"), "{w}");
    assert!(!w.contains("body \"link2\".inertia"), "{w}");

    let src = with(r#"{ body = "link2", mass = -1.0 }"#);
    let e = codegen::spec::load("arm.toml", &src, &overrides)
        .err()
        .unwrap()
        .render();
    assert!(e.contains("payload mass -1"), "{e}");
    let col = src.lines().nth(lines + 2).unwrap().find("-1.0").unwrap() + 1;
    assert!(e.contains(&format!("arm.toml:{}:{col}", lines + 3)), "{e}");

    // Each of its mistakes is reported, not only the first one met.
    let src = with(r#"{ mass = "heavy", com = [0.1, 0.2], inertia = { ixx = "x" } }"#);
    let e = codegen::spec::load("arm.toml", &src, &overrides)
        .err()
        .unwrap()
        .render();
    for key in [
        "scene.payload.body",
        "scene.payload.mass",
        "scene.payload.com",
        "scene.payload.inertia.iyy",
        "scene.payload.inertia.ixx",
    ] {
        assert!(e.contains(&format!("^ {key}\n")), "{key}:\n{e}");
    }

    // A physical payload on a physical body: no warning.
    let src =
        with(r#"{ body = "link2", mass = 1.0, inertia = { ixx = 0.01, iyy = 0.01, izz = 0.01 } }"#);
    let loaded = codegen::spec::load("arm.toml", &src, &overrides).unwrap();
    assert!(loaded.warnings.is_empty(), "{}", loaded.warnings.render());
}
