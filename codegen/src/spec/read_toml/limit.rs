//! A joint's `limit = { lower, upper, velocity }`: its range (rad or m; angle strings such as
//! `"-170 deg"` on a revolute joint, as for `home`) and, optionally, its speed bound (rad/s or
//! m/s), URDF's names and units. Limits are carried beside the model for the CLI tools
//! (`codegen excite`), never part of the dynamics (docs/spec.md, "Joint limits").

use super::keys::LIMIT_KEYS;
use super::{Reader, get};
use crate::spec::RANGE_HINT;
use crate::spec::ir::{Kind, LimitSpec};

impl Reader<'_> {
    /// `limit` on a joint of kind `kind` (`None` when not written, or after an error, which is
    /// reported at the key).
    pub(super) fn limit(
        &mut self,
        v: &super::Val<'_>,
        key: &str,
        kind: Option<Kind>,
    ) -> Option<LimitSpec> {
        match kind {
            Some(Kind::Revolute | Kind::Prismatic) => {}
            Some(k) => {
                self.err(
                    format!(
                        "`limit` is for revolute and prismatic joints, not {}",
                        k.word()
                    ),
                    key,
                    v.span(),
                )
                .hint = Some(
                    "a joint of one coordinate may carry its range; remove `limit` here (a universal or spherical joint's angles have no range in nocdyn)"
                        .into(),
                );
                return None;
            }
            None => return None,
        }
        let t = self.table(v, key)?;
        self.unknown_keys(t, LIMIT_KEYS, key);
        let bound = |r: &mut Self, k: &str| -> Option<f64> {
            let Some(x) = get(t, k) else {
                r.missing(
                    k,
                    key,
                    v.span(),
                    "limit = { lower = …, upper = …, velocity = … } (velocity optional)",
                );
                return None;
            };
            let full = format!("{key}.{k}");
            let y = if kind == Some(Kind::Revolute) {
                r.angle(x, &full)
            } else {
                r.number(x, &full)
            }?;
            if !crate::spec::in_range(y) {
                r.err(format!("`{k}` ({y:e}) is out of range"), &full, x.span())
                    .hint = Some(RANGE_HINT.into());
                return None;
            }
            Some(y)
        };
        let lower = bound(self, "lower");
        let upper = bound(self, "upper");
        let velocity = match get(t, "velocity") {
            None => Some(None),
            Some(x) => {
                let full = format!("{key}.velocity");
                match self.number(x, &full) {
                    Some(s) if s > 0.0 && crate::spec::in_range(s) => Some(Some(s)),
                    Some(s) => {
                        self.err(
                            format!("`velocity` must be positive and within ±1e9, not {s}"),
                            &full,
                            x.span(),
                        )
                        .hint = Some(
                            "the bound on |q̇| in rad/s (m/s for a prismatic joint); leave it out for no speed bound"
                                .into(),
                        );
                        None
                    }
                    None => None,
                }
            }
        };
        let (lower, upper, velocity) = (lower?, upper?, velocity?);
        if lower >= upper {
            let full = format!("{key}.upper");
            let span = get(t, "upper").map_or(v.span(), |x| x.span());
            self.err(
                format!("`upper` ({upper}) must be greater than `lower` ({lower})"),
                &full,
                span,
            )
            .hint = Some(
                "the joint moves in [lower, upper]; a joint that does not move is `kind = \"fixed\"`"
                    .into(),
            );
            return None;
        }
        Some(LimitSpec {
            lower,
            upper,
            velocity,
            span: Some(v.span()),
        })
    }
}
