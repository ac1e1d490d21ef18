//! `[parameters]` and the expressions that use them: a numeric value may be a string such as
//! `"r_base * cos(120 deg)"` (grammar in [`crate::spec::expr`]), evaluated when the spec is
//! read, with its errors pointing into the string.

use std::ops::Range;

use toml::de::{DeTable, DeValue};

use super::{Reader, Val, key_span};
use crate::spec::expr::{self, ExprError, Value};
use crate::spec::suggest_hint;

/// Names an expression cannot redefine.
const RESERVED: &[&str] = &[
    "pi", "i", "deg", "rad", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "abs",
    "hypot", "min", "max",
];

/// A parameter as written, before evaluation.
struct Pending<'t, 'i> {
    name: String,
    value: &'t Val<'i>,
    key: String,
    /// The names it refers to.
    refers: Vec<String>,
}

impl Reader<'_> {
    /// The value of a name in an expression: the pattern copy's number `i` and its own
    /// parameters, then the file's `[parameters]`.
    pub(super) fn lookup(&self, name: &str) -> Option<Value> {
        if let Some(c) = &self.copy {
            if name == "i" {
                return Some(Value::Scalar(c.index as f64));
            }
            if let Some((_, v)) = c.params.iter().find(|(n, _)| n == name) {
                return Some(v.clone());
            }
        }
        self.params
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
    }

    /// Evaluates the expression `s`, written at `v`; reports its error at `key` and returns
    /// `None` on failure.
    pub(super) fn expression(&mut self, s: &str, v: &Val<'_>, key: &str) -> Option<f64> {
        let result = expr::eval(s, &|n| self.lookup(n));
        match result {
            Ok(x) => Some(x),
            // A name whose own value failed is already reported.
            Err(e)
                if e.unknown
                    .as_ref()
                    .is_some_and(|u| self.declared.contains(u)) =>
            {
                None
            }
            Err(e) => {
                self.expression_error(s, &e, v, key);
                None
            }
        }
    }

    fn expression_error(&mut self, s: &str, e: &ExprError, v: &Val<'_>, key: &str) {
        // The string's content starts after its opening quote (exact for strings without
        // escapes, which expressions have no use for).
        let span = v.span();
        let start = (span.start + 1 + e.at.start).min(span.end);
        let end = (span.start + 1 + e.at.end).clamp(start, span.end);
        let at: Range<usize> = if end > start { start..end } else { span };
        let mut names: Vec<String> = self.declared.clone();
        if self.copy.is_some() {
            names.push("i".into());
        }
        let trailing = e.message.contains("after a value");
        let hint = match &e.unknown {
            Some(u) if trailing => suggest_hint(u, &["deg", "rad"]).unwrap_or_else(|| {
                "write a number in SI units, an angle such as \"90 deg\" or \"pi/2\", or an expression joining values with + - * / ^".into()
            }),
            Some(u) => {
                let mut candidates: Vec<&str> = names.iter().map(String::as_str).collect();
                candidates.extend(["pi", "deg", "rad"]);
                suggest_hint(u, &candidates).unwrap_or_else(|| {
                    if names.is_empty() {
                        format!("define `{u}` under [parameters], e.g. `{u} = 0.2`")
                    } else {
                        format!(
                            "define `{u}` under [parameters]; defined here: {}",
                            names.join(", ")
                        )
                    }
                })
            }
            None => "an expression combines numbers, [parameters], `pi`, units `deg`/`rad`, + - * / ^, parentheses and sin cos tan asin acos atan atan2 sqrt abs hypot min max (docs/spec.md, \"Parameters and expressions\")".into(),
        };
        self.err(format!("in {s:?}: {}", e.message), key, at).hint = Some(hint);
    }

    /// `[parameters]` (or a pattern's `parameters`): each a number, an expression, or an array
    /// of them; evaluated in the order their references need, whatever the order written.
    pub(super) fn parameter_table(&mut self, t: &DeTable<'_>, path: &str) -> Vec<(String, Value)> {
        let mut pending: Vec<Pending<'_, '_>> = Vec::new();
        for (k, v) in t.iter() {
            let name = k.get_ref().to_string();
            let key = format!("{path}.{name}");
            let valid = name
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !valid || RESERVED.contains(&name.as_str()) {
                let why = if valid {
                    "is reserved (a constant, a unit, a function or the copy number `i`)"
                } else {
                    "is not a name: use ASCII letters, digits and `_`, not starting with a digit"
                };
                self.err(format!("parameter `{name}` {why}"), &key, k.span());
                continue;
            }
            let mut refers = Vec::new();
            let mut texts = |v: &Val<'_>| {
                if let DeValue::String(s) = v.get_ref() {
                    refers.extend(expr::names(s));
                }
            };
            match v.get_ref() {
                DeValue::Array(a) => a.iter().for_each(&mut texts),
                _ => texts(v),
            }
            if !self.declared.contains(&name) {
                self.declared.push(name.clone());
            }
            pending.push(Pending {
                name,
                value: v,
                key,
                refers,
            });
        }
        let mut done: Vec<(String, Value)> = Vec::new();
        // The parameters are evaluated in passes: each pass evaluates, in table order, every
        // parameter that refers to no parameter still waiting, and a pass that makes no
        // progress leaves a cycle (unknown names are reported at evaluation). That order is a
        // parameter's depth (the longest chain of references below it) and then its place in
        // the table; computed here in one walk of the references rather than pass by pass,
        // which took cubic time in the length of a chain (6,000 chained parameters: 78 s).
        let depth = reference_depths(&pending);
        let mut order: Vec<usize> = (0..pending.len()).filter(|&k| depth[k].is_some()).collect();
        order.sort_by_key(|&k| depth[k]);
        for &k in &order {
            let p = &pending[k];
            if let Some(v) = self.parameter_value(p.value, &p.key) {
                self.push_parameter(&p.name, v, &mut done);
            }
        }
        // What is left waits on a cycle: reported at each such parameter, with the names it
        // still waits on, as the passes left them.
        let waiting: std::collections::HashSet<&str> = pending
            .iter()
            .zip(&depth)
            .filter(|(_, d)| d.is_none())
            .map(|(p, _)| p.name.as_str())
            .collect();
        for p in pending
            .iter()
            .zip(&depth)
            .filter(|(_, d)| d.is_none())
            .map(|(p, _)| p)
        {
            let waits: Vec<&str> = p
                .refers
                .iter()
                .filter(|r| waiting.contains(r.as_str()))
                .map(String::as_str)
                .collect();
            let span = key_span(t, &p.name).unwrap_or(p.value.span());
            self.err(
                format!(
                    "parameter `{}` depends on itself through {}",
                    p.name,
                    waits.join(", ")
                ),
                &p.key,
                span,
            )
            .hint = Some("parameters may refer to each other, but not in a cycle".into());
        }
        done
    }

    /// Makes a parameter visible to the ones evaluated after it.
    fn push_parameter(&mut self, name: &str, v: Value, done: &mut Vec<(String, Value)>) {
        done.push((name.to_owned(), v.clone()));
        match &mut self.copy {
            Some(c) => c.params.push((name.to_owned(), v)),
            None => self.params.push((name.to_owned(), v)),
        }
    }

    fn parameter_value(&mut self, v: &Val<'_>, key: &str) -> Option<Value> {
        match v.get_ref() {
            DeValue::Array(a) => {
                let mut out = Vec::with_capacity(a.len());
                let mut ok = true;
                for (k, e) in a.iter().enumerate() {
                    match self.number(e, &format!("{key}[{k}]")) {
                        Some(x) => out.push(x),
                        None => ok = false,
                    }
                }
                if a.is_empty() {
                    self.err("an array parameter needs at least one value", key, v.span());
                    return None;
                }
                ok.then_some(Value::Array(out))
            }
            _ => self.number(v, key).map(Value::Scalar),
        }
    }
}

/// Each pending parameter's depth: 0 when it refers to no other pending parameter, else one
/// more than the deepest it refers to; `None` when it refers, directly or through others, to a
/// cycle. Iterative (a chain of a million parameters must not overflow the stack) and linear
/// in the number of references.
fn reference_depths(pending: &[Pending<'_, '_>]) -> Vec<Option<usize>> {
    #[derive(Clone, Copy)]
    enum State {
        New,
        Open,
        Done(Option<usize>),
    }
    let index: std::collections::HashMap<&str, usize> = pending
        .iter()
        .enumerate()
        .map(|(k, p)| (p.name.as_str(), k))
        .collect();
    let deps: Vec<Vec<usize>> = pending
        .iter()
        .map(|p| {
            p.refers
                .iter()
                .filter_map(|r| index.get(r.as_str()).copied())
                .collect()
        })
        .collect();
    let mut state = vec![State::New; pending.len()];
    for root in 0..pending.len() {
        if !matches!(state[root], State::New) {
            continue;
        }
        // (parameter, next reference to look at, depth so far: None once a cycle is met)
        let mut stack: Vec<(usize, usize, Option<usize>)> = vec![(root, 0, Some(0))];
        state[root] = State::Open;
        while let Some(top) = stack.last_mut() {
            let (k, next, depth) = *top;
            if next < deps[k].len() {
                top.1 += 1;
                let d = deps[k][next];
                match state[d] {
                    State::New => {
                        state[d] = State::Open;
                        stack.push((d, 0, Some(0)));
                    }
                    State::Open => top.2 = None,
                    State::Done(dd) => {
                        top.2 = match (depth, dd) {
                            (Some(a), Some(b)) => Some(a.max(b + 1)),
                            _ => None,
                        }
                    }
                }
            } else {
                stack.pop();
                state[k] = State::Done(depth);
                if let Some(parent) = stack.last_mut() {
                    parent.2 = match (parent.2, depth) {
                        (Some(a), Some(b)) => Some(a.max(b + 1)),
                        _ => None,
                    };
                }
            }
        }
    }
    state
        .into_iter()
        .map(|s| match s {
            State::Done(d) => d,
            _ => None,
        })
        .collect()
}
