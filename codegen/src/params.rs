//! The run-time parameters of parallel and closed-loop modules (`[scene] parameters =
//! "runtime"`, `runtime_inertia`): where each value sits in the flat `Params` array
//! ([`Layout`]), the symbolic inputs that stand for them in the DAG, and the emitted `NP`
//! constant and `Params` struct.

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::payload::Payload;

use crate::emit;
use crate::scalar::{Sx, inputs};
use crate::spec;
use crate::sym::Arg;

/// Which values of a parallel module are run-time parameters (`Arg::P`), and where they sit in
/// the generated `Params::to_array`: entries 0–9 the platform payload (mass, mass centre,
/// inertia `xx, xy, xz, yy, yz, zz`, platform frame; reserved even without one), then, per leg
/// joint `3·leg + k`, the viscous coefficients and the Coulomb levels (with `friction`), then
/// the rotor inertias (with `rotor_inertia`), then ten entries per run-time body
/// (`[scene] runtime_inertia`, ordered as the payload's; [`Layout::body_base`]). Closed loops
/// use the same layout with the tree joints and tree bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Layout {
    /// The platform payload.
    pub payload: bool,
    /// The leg joints' viscous and Coulomb friction.
    pub friction: bool,
    /// The leg joints' rotor inertias.
    pub rotor_inertia: bool,
    /// `v_s` of the regularized Coulomb law.
    pub coulomb_velocity: f64,
    /// Number of run-time bodies (`[scene] runtime_inertia`).
    pub bodies: usize,
}

impl Layout {
    /// The layout of a module's run-time parameters (`None`: constants).
    pub fn of(params: Option<&crate::spec::RuntimeParams>) -> Layout {
        match params {
            None => Layout::default(),
            Some(p) => Layout {
                payload: p.payload.is_some(),
                friction: p.leg_friction,
                rotor_inertia: p.leg_rotor_inertia,
                coulomb_velocity: p.coulomb_velocity,
                bodies: p.bodies.len(),
            },
        }
    }

    /// Whether the module takes `Params`.
    pub fn any(&self) -> bool {
        self.payload || self.drives() || self.bodies > 0
    }

    /// Whether the leg joints' drives are run-time parameters.
    pub fn drives(&self) -> bool {
        self.friction || self.rotor_inertia
    }

    /// First index of the viscous coefficients, the Coulomb levels and the rotor inertias of
    /// `nlj` leg joints (`None` where absent), and the total count.
    pub fn offsets(&self, nlj: usize) -> (Option<usize>, Option<usize>, Option<usize>, usize) {
        let mut at = 10;
        let mut take = |on: bool| {
            on.then(|| {
                let k = at;
                at += nlj;
                k
            })
        };
        let v = take(self.friction);
        let c = take(self.friction);
        let a = take(self.rotor_inertia);
        (v, c, a, at)
    }

    /// First index of run-time body `k`'s ten parameters, with `nlj` leg (or tree) joints.
    pub fn body_base(&self, nlj: usize, k: usize) -> usize {
        self.offsets(nlj).3 + 10 * k
    }

    /// Number of run-time parameters (`Params::to_array`), with `nlj` leg (or tree) joints.
    pub fn count(&self, nlj: usize) -> usize {
        self.body_base(nlj, self.bodies)
    }
}

/// The drives of `nlj` joints of the `Arg::P` inputs.
pub(crate) fn drive_inputs(nlj: usize, layout: &Layout) -> runtime::drive::DriveInputs<Sx> {
    let (v, c, a, np) = layout.offsets(nlj);
    let p = inputs(Arg::P, np);
    let at = |k: Option<usize>| k.map(|k| p[k..k + nlj].to_vec());
    runtime::drive::DriveInputs {
        viscous: at(v),
        coulomb: at(c),
        armature: at(a),
        coulomb_velocity: layout.coulomb_velocity,
    }
}

/// The payload of the `Arg::P` inputs (entries 0–9).
pub(crate) fn payload_inputs() -> Payload<Sx> {
    payload_inputs_at(0)
}

/// A rigid body's parameters of the `Arg::P` inputs `at..at + 10`, ordered as the payload's.
pub(crate) fn payload_inputs_at(at: usize) -> Payload<Sx> {
    let p = inputs(Arg::P, at + 10);
    let p = &p[at..];
    Payload {
        mass: p[0],
        com: [p[1], p[2], p[3]],
        inertia: [[p[4], p[5], p[6]], [p[5], p[7], p[8]], [p[6], p[8], p[9]]],
    }
}

/// The `NP` constant and the `Params` struct of a module with run-time parameters (parallel
/// mechanisms and closed loops, in [`Layout`]'s layout): the payload's fields (on `payload.0`,
/// its values in that frame), then one array per drive effect over `drives`, of length
/// `per.0` (a constant of the module), each entry a `per.1`, then the run-time bodies' fields
/// (`bodies`, on the model body `frame` names; [`body_params`]).
// The pieces of one struct: kept apart, they would only be regrouped by every caller.
#[allow(clippy::too_many_arguments)]
pub(crate) fn params_items(
    layout: &Layout,
    payload: Option<(String, f64, runtime::model::Vec3, runtime::model::Mat3)>,
    drives: &[&runtime::model::Drive],
    per: (&str, &str),
    what: &str,
    bodies: &[crate::spec::RuntimeBody],
    frame: &dyn Fn(usize) -> String,
) -> TokenStream {
    let real = crate::emit::real();
    let (mut fields, mut default, mut fill) = match &payload {
        Some((on, m, c, i)) => payload_params(on, *m, c, i),
        None => (quote!(), quote!(), quote!()),
    };
    let (v0, c0, a0, _) = layout.offsets(drives.len());
    let np = layout.count(drives.len());
    let len = proc_macro2::Ident::new(per.0, proc_macro2::Span::call_site());
    let mut drive_field =
        |at: Option<usize>,
         name: &str,
         doc: &str,
         value: &dyn Fn(&runtime::model::Drive) -> f64| {
            let Some(at) = at else { return };
            let ident = proc_macro2::Ident::new(name, proc_macro2::Span::call_site());
            let vals: Vec<_> = drives.iter().map(|d| emit::float_lit(value(d))).collect();
            let at = Literal::usize_unsuffixed(at);
            let doc = format!(" {doc}, per {}.", per.1);
            fields.extend(quote! {
                #[doc = #doc]
                pub #ident: [#real; #len],
            });
            default.extend(quote!(#ident: [#(#vals),*],));
            fill.extend(quote! {
                let mut i = 0;
                while i < #len {
                    a[#at + i] = self.#ident[i];
                    i += 1;
                }
            });
        };
    drive_field(
        v0,
        "damping",
        "Viscous friction (N·m·s/rad or N·s/m)",
        &|d| d.viscous,
    );
    drive_field(
        c0,
        "friction",
        "Coulomb friction level (N·m or N), regularized as in the spec docs",
        &|d| d.coulomb,
    );
    drive_field(
        a0,
        "armature",
        "Reflected rotor inertia (kg·m² or kg)",
        &|d| d.armature,
    );
    let (body_items, body_fields, body_default, body_fill) =
        body_params(bodies, frame, layout.body_base(drives.len(), 0));
    fields.extend(body_fields);
    default.extend(body_default);
    fill.extend(body_fill);
    let np = Literal::usize_unsuffixed(np);
    let doc = format!(
        " Run-time parameters (`[scene] parameters = \"runtime\"`): {what}, so one binary serves several tools or drive calibrations. SI units. The functions of the masses take them last; the kinematics do not."
    );
    quote! {
        #body_items
        /// Number of run-time parameters in [`Params::to_array`].
        pub const NP: usize = #np;
        #[doc = #doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Params {
            #fields
        }
        impl Params {
            /// The values of the spec (what a module with constants would fold in).
            pub const DEFAULT: Params = Params {
                #default
            };
            /// The flat layout the generated functions read.
            pub fn to_array(&self) -> [#real; NP] {
                let mut a = [0.0; NP];
                #fill
                a
            }
        }
        impl Default for Params {
            fn default() -> Self {
                Self::DEFAULT
            }
        }
    }
}

/// The payload's fields of a `Params` struct, their `DEFAULT` values and their part of
/// `to_array` (entries 0–9: mass, mass centre, inertia `xx, xy, xz, yy, yz, zz`); `on` names the
/// frame's owner ("body `link6`", "the platform").
pub(crate) fn payload_params(
    on: &str,
    m: f64,
    c: &runtime::model::Vec3,
    i: &runtime::model::Mat3,
) -> (
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
) {
    let real = crate::emit::real();
    use quote::quote;
    let doc_m = format!(" Payload mass (kg), rigidly attached to {on}.");
    let doc_c = format!(" Payload mass centre in {on}'s frame (m).");
    let doc_i = format!(" Payload inertia about its mass centre, {on}'s axes (kg·m²), symmetric.");
    let m = emit::float_lit(m);
    let c: Vec<_> = c.iter().map(|v| emit::float_lit(*v)).collect();
    let rows: Vec<_> = i
        .iter()
        .map(|r| {
            let r: Vec<_> = r.iter().map(|v| emit::float_lit(*v)).collect();
            quote!([#(#r),*])
        })
        .collect();
    (
        quote! {
            #[doc = #doc_m]
            pub payload_mass: #real,
            #[doc = #doc_c]
            pub payload_com: [#real; 3],
            #[doc = #doc_i]
            pub payload_inertia: [[#real; 3]; 3],
        },
        quote! {
            payload_mass: #m,
            payload_com: [#(#c),*],
            payload_inertia: [#(#rows),*],
        },
        quote! {
            a[0] = self.payload_mass;
            a[1] = self.payload_com[0];
            a[2] = self.payload_com[1];
            a[3] = self.payload_com[2];
            a[4] = self.payload_inertia[0][0];
            a[5] = self.payload_inertia[0][1];
            a[6] = self.payload_inertia[0][2];
            a[7] = self.payload_inertia[1][1];
            a[8] = self.payload_inertia[1][2];
            a[9] = self.payload_inertia[2][2];
        },
    )
}

/// The run-time bodies' items of a module (`[scene] runtime_inertia`; nothing without any):
/// `NB` and `RUNTIME_BODY_NAMES` (outside `Params`), the fields `body_mass`, `body_com` and
/// `body_inertia` of `Params`, their `DEFAULT` values and their part of `to_array` (ten entries
/// per body from `base`, ordered as the payload's). `frame` names the owner of the frame of a
/// model body ("model body `link6`", "the platform").
pub(crate) fn body_params(
    bodies: &[spec::RuntimeBody],
    frame: &dyn Fn(usize) -> String,
    base: usize,
) -> (
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
) {
    let real = crate::emit::real();
    use proc_macro2::Literal;
    use quote::quote;
    if bodies.is_empty() {
        return (quote!(), quote!(), quote!(), quote!());
    }
    let nb = Literal::usize_unsuffixed(bodies.len());
    let base = Literal::usize_unsuffixed(base);
    let names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
    let mut names_doc = vec![
        " The bodies whose inertial parameters are run-time parameters (`[scene] runtime_inertia`), \
         in the order of `Params::body_mass`, `body_com` and `body_inertia`. Each body's mass \
         centre and inertia are in the frame of the model body it is part of (after fixed-joint \
         merging):"
            .to_string(),
    ];
    for (k, b) in bodies.iter().enumerate() {
        names_doc.push(format!(" {k}. `{}`: {}.", b.name, frame(b.body)));
    }
    let mass: Vec<_> = bodies.iter().map(|b| emit::float_lit(b.mass)).collect();
    let com: Vec<_> = bodies
        .iter()
        .map(|b| {
            let c: Vec<_> = b.com.iter().map(|v| emit::float_lit(*v)).collect();
            quote!([#(#c),*])
        })
        .collect();
    let inertia: Vec<_> = bodies
        .iter()
        .map(|b| {
            let rows: Vec<_> = b
                .inertia
                .iter()
                .map(|r| {
                    let r: Vec<_> = r.iter().map(|v| emit::float_lit(*v)).collect();
                    quote!([#(#r),*])
                })
                .collect();
            quote!([#(#rows),*])
        })
        .collect();
    (
        quote! {
            /// Number of bodies with run-time inertial parameters ([`RUNTIME_BODY_NAMES`]).
            pub const NB: usize = #nb;
            #(#[doc = #names_doc])*
            pub const RUNTIME_BODY_NAMES: [&str; NB] = [#(#names),*];
        },
        quote! {
            /// Mass of each body of [`RUNTIME_BODY_NAMES`] (kg).
            pub body_mass: [#real; NB],
            /// Mass centre of each body of [`RUNTIME_BODY_NAMES`] (m), in the frame of the
            /// model body it is part of (listed there).
            pub body_com: [[#real; 3]; NB],
            /// Inertia of each body of [`RUNTIME_BODY_NAMES`] about its mass centre (kg·m²,
            /// symmetric), in the axes of the model body it is part of.
            pub body_inertia: [[[#real; 3]; 3]; NB],
        },
        quote! {
            body_mass: [#(#mass),*],
            body_com: [#(#com),*],
            body_inertia: [#(#inertia),*],
        },
        quote! {
            let mut k = 0;
            while k < NB {
                let b = #base + 10 * k;
                let (c, j) = (&self.body_com[k], &self.body_inertia[k]);
                a[b] = self.body_mass[k];
                a[b + 1] = c[0];
                a[b + 2] = c[1];
                a[b + 3] = c[2];
                a[b + 4] = j[0][0];
                a[b + 5] = j[0][1];
                a[b + 6] = j[0][2];
                a[b + 7] = j[1][1];
                a[b + 8] = j[1][2];
                a[b + 9] = j[2][2];
                k += 1;
            }
        },
    )
}
