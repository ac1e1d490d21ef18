//! The four parallel specs, one function each, in the order they are written.

use std::path::Path;

use super::*;

const SLIDING_HEXAPOD_HEADER: &str = "\nSliding-leg (fixed-length leg) hexapod, 6-PUS, in the manner of the HexaM (Toyoda), Hexaglide\n(ETH) and Linapod (Stuttgart) machines (docs/method.md, \"Test cases from the literature\"; Sinatra & Xi 2008). ILLUSTRATIVE\nnumbers, not a real machine: six vertical rails on a semi-regular hexagon of radius 0.6 m (pairs\n+-10 deg about 90, 210, 330 deg), an actuated slider (P, along z) on each, a U on the slider,\na fixed-length leg of 0.6 m (steel tube: 0.8 kg, radius 15 mm) to an S joint on the platform, whose\njoints lie on a semi-regular hexagon of radius 0.25 m (pairs +-15 deg about 30, 150, 270 deg),\n5 cm below the platform frame. Base and platform hexagons are not similar (no architecture\nsingularity). Platform: 8 kg disc (radius 0.3 m, 30 mm thick), mass centre at the platform frame\norigin. Sliders: 1.5 kg boxes 0.1 x 0.1 x 0.15 m, mass centre 3 cm radially outward of the U\ncentre. Home: platform frame at (0, 0, 1.0) m, identity orientation; every slider's coordinate is\nmeasured from its home height.\n";

const RUS_HEXAPOD_HEADER: &str = "\nRotary hexapod, 6-RUS (revolute-actuated cranks, as in the common servo-driven Stewart\nplatforms). ILLUSTRATIVE numbers, not a real machine: six motor shafts on a semi-regular hexagon\nof radius 0.2 m (pairs +-15 deg about 90, 210, 330 deg) with horizontal axes tangent to that\ncircle; a 0.1 m crank on each (actuated R; at home the crank points radially outward and is\nhorizontal); a U at the crank tip; a 0.3 m rod (0.15 kg, radius 5 mm) to an S joint on the\nplatform, whose joints lie on a semi-regular hexagon of radius 0.12 m (pairs +-20 deg about 30,\n150, 270 deg) in the plane of the platform frame. Base and platform hexagons are not similar.\nCranks: 0.2 kg bars 0.1 m long, mass centre at mid-length. Platform: 1.2 kg disc (radius 0.15 m,\n10 mm thick), mass centre at the platform frame origin. Home: platform frame above the base\ncentre at the height where every rod meets its platform joint with the cranks horizontal,\nidentity orientation.\n";

const AGILE_EYE_HEADER: &str = "\nAgile Eye: spherical 3-RRR camera-orienting mechanism after C. M. Gosselin and J.-F. Hamel,\n\"The agile eye: a high-performance three-degree-of-freedom camera-orienting device\", IEEE ICRA\n1994, pp. 781-786 (geometry as in Bonev, Chablat & Wenger, ICRA 2006: all adjacent joint axes\northogonal). Every axis passes through the centre of rotation, the origin. At home (identity)\nleg i has base axis u_i, intermediate axis w_i and platform axis v_i with (u, w, v) = (x, y, z),\n(y, z, x), (z, x, y); the base revolutes are actuated, and at home the actuation matrix is the\nidentity. Masses and inertias are ILLUSTRATIVE: each link is a thin 90-degree circular arc about\nthe centre (proximal link: 0.25 kg, radius 0.12 m, from the u axis to the w axis; distal link:\n0.2 kg, radius 0.10 m, from w to v) plus 2e-5 kg m^2 on the diagonal for its cross-section; the\ncamera platform is 0.3 kg, I = diag(4e-4, 4e-4, 2.5e-4) kg m^2, mass centre 2 cm along its z\naxis. The joints sit on their axes at 0.15 m (base), 0.12 m (intermediate) and 0.10 m\n(platform) from the centre; each body frame has the base orientation at home.\n";

/// The `[mechanism]` and `[platform]` tables.
fn head(s: &mut Spec, name: &str, source: &str, platform: &[(&str, String)]) {
    s.table(
        "[mechanism]",
        &[
            ("name", format!("\"{name}\"")),
            ("gravity", vec(&[0.0, 0.0, -9.81])),
            ("source", format!("\"{source}\"")),
        ],
    );
    s.table("[platform]", platform);
}

/// A pose platform's table at `home`, identity orientation.
fn pose_platform(body: &str, home: V3) -> Vec<(&'static str, String)> {
    vec![
        ("body", format!("\"{body}\"")),
        ("coordinates", "\"pose\"".into()),
        ("home", origin(home, Some([0.0, 0.0, 0.0]))),
    ]
}

// ---------------------------------------------------------------- 2. sliding-leg hexapod (6-PUS)
pub fn sliding_hexapod(dir: &Path) -> std::io::Result<()> {
    let (rb, ab) = (0.6, 10.0); // rail circle radius (m), pair half-angle (deg)
    let (rp, ap) = (0.25, 15.0); // platform joint circle radius, pair half-angle
    let zp = -0.05; // S centres below the platform frame
    let home = [0.0, 0.0, 1.0];
    let rod_len = 0.6;
    let (m_slider, m_rod, m_plat) = (1.5, 0.8, 8.0);
    let rails = semi_regular(rb, ab, 90.0, 0.0);
    let plat_pts = semi_regular(rp, ap, 30.0, zp);
    let mut s = Spec::new(SLIDING_HEXAPOD_HEADER);
    head(
        &mut s,
        "sliding_hexapod",
        "illustrative HexaM/Linapod-like 6-PUS hexapod (see the header comment)",
        &pose_platform("platform", home),
    );
    s.body(
        "platform",
        m_plat,
        [0.0, 0.0, 0.0],
        &rod_inertia(m_plat, 0.03, 0.3),
    );
    // Rail (pair k, −) meets the platform joint (pair k, +) and rail (pair k, +) the joint
    // (pair k + 1, −): 35 degrees apart in azimuth.
    let (mut points, mut dirs) = (Vec::new(), Vec::new());
    for i in 0..6 {
        let n = i + 1;
        let rail = rails[i];
        let p_local = plat_pts[(i + 1) % 6];
        let p_world = add(home, p_local);
        let horiz = norm(sub([p_world[0], p_world[1], 0.0], [rail[0], rail[1], 0.0]));
        let z_slider = p_world[2] - (rod_len * rod_len - horiz * horiz).sqrt();
        let u_centre = [rail[0], rail[1], z_slider];
        let d = unit(sub(p_world, u_centre));
        let rpy = rpy_of(frame_with_z(d));
        let tip = add(u_centre, mat_vec(rpy_matrix(rpy), [0.0, 0.0, rod_len]));
        check_closure(&format!("sliding_hexapod leg {n}"), tip, p_world);
        points.push(sub(p_world, home));
        dirs.push(d);
        let radial = unit([rail[0], rail[1], 0.0]);
        s.comment(&format!(
            "Leg {n}: rail at {}, slider home height {z_slider:.6} m, platform joint {}",
            vec(&rail[..2]),
            vec(&p_local)
        ));
        let (slider, leg) = (format!("slider{n}"), format!("leg{n}"));
        s.body(
            &slider,
            m_slider,
            scale(0.03, radial),
            &box_inertia(m_slider, 0.1, 0.1, 0.15),
        );
        s.body(
            &leg,
            m_rod,
            [0.0, 0.0, rod_len / 2.0],
            &rod_inertia(m_rod, rod_len, 0.015),
        );
        s.joint(
            &format!("slide{n}"),
            "P",
            "base",
            &slider,
            JointKeys {
                origin: Some(origin(u_centre, None)),
                axis: Some([0.0, 0.0, 1.0]),
                actuated: true,
                ..Default::default()
            },
        );
        s.joint(
            &format!("u{n}"),
            "U",
            &slider,
            &leg,
            JointKeys {
                origin: Some(origin([0.0, 0.0, 0.0], Some(rpy))),
                ..Default::default()
            },
        );
        s.joint(
            &format!("s{n}"),
            "S",
            &leg,
            "platform",
            JointKeys {
                origin: Some(origin([0.0, 0.0, rod_len], None)),
                child_origin: Some(origin(p_local, None)),
                ..Default::default()
            },
        );
    }
    lean_scene(&mut s);
    s.write(dir, "sliding_hexapod.toml")?;
    println!("  cond(A) {}", g(plucker_condition(&points, &dirs), 3));
    Ok(())
}

// ---------------------------------------------------------------- 3. rotary hexapod (6-RUS)
pub fn rus_hexapod(dir: &Path) -> std::io::Result<()> {
    let (rb, ab) = (0.2, 15.0); // motor shafts: circle radius (m), pair half-angle (deg)
    let (rp, ap) = (0.12, 20.0); // platform joints
    let (crank, rod_len) = (0.1, 0.3);
    let (m_crank, m_rod, m_plat) = (0.2, 0.15, 1.2);
    let motors = semi_regular(rb, ab, 90.0, 0.0);
    let plat_pts = semi_regular(rp, ap, 30.0, 0.0);
    let partner = |i: usize| (i + 1) % 6; // 25 degrees apart in azimuth
    let mut s = Spec::new(RUS_HEXAPOD_HEADER);
    // Platform height: every rod has the same length by symmetry.
    let radial_of = |m: V3| unit([m[0], m[1], 0.0]);
    let t0 = add(motors[0], scale(crank, radial_of(motors[0])));
    let p0 = plat_pts[partner(0)];
    let horiz = norm(sub([p0[0], p0[1], 0.0], [t0[0], t0[1], 0.0]));
    let height = (rod_len * rod_len - horiz * horiz).sqrt();
    let home = [0.0, 0.0, height];
    head(
        &mut s,
        "rus_hexapod",
        "illustrative rotary (6-RUS) hexapod (see the header comment)",
        &pose_platform("platform", home),
    );
    s.body(
        "platform",
        m_plat,
        [0.0, 0.0, 0.0],
        &rod_inertia(m_plat, 0.01, 0.15),
    );
    let (mut points, mut dirs) = (Vec::new(), Vec::new());
    for i in 0..6 {
        let n = i + 1;
        let radial = radial_of(motors[i]);
        // Crank frame: x along the crank (radial), y up, z = x × y (the shaft axis, tangential).
        let rc = columns(radial, [0.0, 0.0, 1.0], cross(radial, [0.0, 0.0, 1.0]));
        let rpy_c = rpy_of(rc);
        let rc2 = rpy_matrix(rpy_c);
        let tip = add(motors[i], mat_vec(rc2, [crank, 0.0, 0.0]));
        let p_local = plat_pts[partner(i)];
        let p_world = add(home, p_local);
        let d = unit(sub(p_world, tip));
        let ru = frame_with_z(d);
        let rpy_u = rpy_of(mat_mul(transpose(rc2), ru)); // the U frame in the crank frame
        let ru2 = mat_mul(rc2, rpy_matrix(rpy_u));
        let end = add(tip, mat_vec(ru2, [0.0, 0.0, rod_len]));
        check_closure(&format!("rus_hexapod leg {n}"), end, p_world);
        points.push(sub(p_world, home));
        dirs.push(d);
        s.comment(&format!(
            "Leg {n}: shaft at {}, platform joint {}",
            vec(&motors[i][..2]),
            vec(&p_local)
        ));
        let (crank_body, rod) = (format!("crank{n}"), format!("rod{n}"));
        let crank_inertia = box_inertia(m_crank, crank, 0.02, 0.01);
        s.body(
            &crank_body,
            m_crank,
            [crank / 2.0, 0.0, 0.0],
            &crank_inertia,
        );
        s.body(
            &rod,
            m_rod,
            [0.0, 0.0, rod_len / 2.0],
            &rod_inertia(m_rod, rod_len, 0.005),
        );
        s.joint(
            &format!("motor{n}"),
            "R",
            "base",
            &crank_body,
            JointKeys {
                origin: Some(origin(motors[i], Some(rpy_c))),
                axis: Some([0.0, 0.0, 1.0]),
                actuated: true,
                ..Default::default()
            },
        );
        s.joint(
            &format!("u{n}"),
            "U",
            &crank_body,
            &rod,
            JointKeys {
                origin: Some(origin([crank, 0.0, 0.0], Some(rpy_u))),
                ..Default::default()
            },
        );
        s.joint(
            &format!("s{n}"),
            "S",
            &rod,
            "platform",
            JointKeys {
                origin: Some(origin([0.0, 0.0, rod_len], None)),
                child_origin: Some(origin(p_local, None)),
                ..Default::default()
            },
        );
    }
    lean_scene(&mut s);
    s.write(dir, "rus_hexapod.toml")?;
    println!(
        "  home height {height:.6} m, cond(A) {}",
        g(plucker_condition(&points, &dirs), 3)
    );
    Ok(())
}

// ---------------------------------------------------------------- 4. Agile Eye (spherical 3-RRR)
pub fn agile_eye(dir: &Path) -> std::io::Result<()> {
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let legs = [(x, y, z), (y, z, x), (z, x, y)];
    let (r_base, r_mid, r_plat) = (0.15, 0.12, 0.10); // where the joints sit on their axes (m)
    let (m_prox, m_dist) = (0.25, 0.2);
    let core = 2e-5;
    let mut s = Spec::new(AGILE_EYE_HEADER);
    head(
        &mut s,
        "agile_eye",
        "Gosselin & Hamel (ICRA 1994) geometry; illustrative masses and inertias",
        &[
            ("body", "\"camera\"".into()),
            ("coordinates", "\"orientation\"".into()),
            ("home", origin([0.0, 0.0, 0.0], Some([0.0, 0.0, 0.0]))),
            ("centre", vec(&[0.0, 0.0, 0.0])),
        ],
    );
    s.body(
        "camera",
        0.3,
        [0.0, 0.0, 0.02],
        &Inertia::Diagonal([4e-4, 4e-4, 2.5e-4]),
    );
    for (i, (u, w, v)) in legs.into_iter().enumerate() {
        let n = i + 1;
        // Body frames keep the base orientation at home; origins on the joint axes.
        let (o1, o2, o3) = (scale(r_base, u), scale(r_mid, w), scale(r_plat, v));
        let (c1, i1) = arc_props(m_prox, r_mid, u, w, core);
        let (c2, i2) = arc_props(m_dist, r_plat, w, v, core);
        s.comment(&format!(
            "Leg {n}: u = {}, w = {}, v = {}",
            vec(&u),
            vec(&w),
            vec(&v)
        ));
        let (proximal, distal) = (format!("proximal{n}"), format!("distal{n}"));
        s.body(&proximal, m_prox, sub(c1, o1), &i1);
        s.body(&distal, m_dist, sub(c2, o2), &i2);
        s.joint(
            &format!("a{n}"),
            "R",
            "base",
            &proximal,
            JointKeys {
                origin: Some(origin(o1, None)),
                axis: Some(u),
                actuated: true,
                ..Default::default()
            },
        );
        s.joint(
            &format!("b{n}"),
            "R",
            &proximal,
            &distal,
            JointKeys {
                origin: Some(origin(sub(o2, o1), None)),
                axis: Some(w),
                ..Default::default()
            },
        );
        s.joint(
            &format!("c{n}"),
            "R",
            &distal,
            "camera",
            JointKeys {
                origin: Some(origin(sub(o3, o2), None)),
                axis: Some(v),
                child_origin: Some(origin(o3, None)),
                ..Default::default()
            },
        );
    }
    s.write(dir, "agile_eye.toml")
}

/// A `[scene]` without the two derivative functions: with a full inertia on every leg body their
/// forward-mode derivatives run to ten times `inverse_dynamics`' operations, and the bundled
/// crate compiles every module twice (`f64` and `f32`).
fn lean_scene(s: &mut Spec) {
    s.comment(
        "Every function but the two derivative ones (ten times inverse_dynamics' operations at 6 DOF",
    );
    s.comment("with full leg inertias): delete this table to have them.");
    s.table(
        "[scene]",
        &[(
            "functions",
            r#"["actuator_rates", "inverse_dynamics", "mass_matrix", "actuator_mass_matrix", "forward_dynamics", "gravity", "coriolis"]"#.into(),
        )],
    );
}
