//! The run's events as JSON text for the bindings (see [`events_json`]).

use super::EventRecord;

/// The events as JSON text, what the Python `Results.attrs["events"]` holds: a list of objects with the keys
/// and order of `Results.events` (written in Rust, not as Python dicts that Python then dumps:
/// for the 40 closing points of a stack that was a few tenths of a millisecond per run). Non-finite
/// numbers are written as Python's `json` writes and reads them (NaN, Infinity).
pub fn events_json(events: &[EventRecord]) -> String {
    fn num(out: &mut String, x: f64) {
        if x.is_finite() {
            out.push_str(&serde_json::to_string(&x).unwrap_or_else(|_| "NaN".into()));
        } else if x.is_nan() {
            out.push_str("NaN");
        } else {
            out.push_str(if x > 0.0 { "Infinity" } else { "-Infinity" });
        }
    }
    fn text(out: &mut String, s: &str) {
        out.push_str(&serde_json::to_string(s).unwrap_or_else(|_| "\"?\"".into()));
    }
    fn nums(out: &mut String, xs: &[f64]) {
        out.push('[');
        for (k, x) in xs.iter().enumerate() {
            if k > 0 {
                out.push_str(", ");
            }
            num(out, *x);
        }
        out.push(']');
    }
    let mut out = String::with_capacity(200 * events.len() + 2);
    out.push('[');
    for (k, e) in events.iter().enumerate() {
        if k > 0 {
            out.push_str(", ");
        }
        out.push_str("{\"t\": ");
        num(&mut out, e.t);
        out.push_str(", \"contact\": ");
        text(&mut out, &e.contact);
        out.push_str(&format!(", \"point\": {}, \"event\": ", e.point));
        text(&mut out, e.kind);
        out.push_str(", \"impulse_n\": ");
        num(&mut out, e.impulse[0]);
        out.push_str(", \"impulse_t\": ");
        nums(&mut out, &e.impulse[1..]);
        out.push_str(", \"energy\": ");
        num(&mut out, e.energy);
        out.push_str(&format!(", \"steps\": {}", e.steps));
        if !e.u_before.is_empty() {
            out.push_str(", \"u_before\": ");
            nums(&mut out, &e.u_before);
            out.push_str(", \"u_after\": ");
            nums(&mut out, &e.u_after);
        }
        if let Some(p) = &e.painleve {
            out.push_str(", \"mu\": ");
            num(&mut out, p.mu);
            out.push_str(", \"mu_critical\": ");
            num(&mut out, p.mu_critical);
            out.push_str(", \"situation\": ");
            text(&mut out, if p.non_unique { "non-unique" } else { "inconsistent" });
            out.push_str(", \"solutions\": [");
            for (j, sol) in p.solutions.iter().enumerate() {
                if j > 0 {
                    out.push_str(", ");
                }
                out.push('[');
                for (i, name) in sol.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    text(&mut out, name);
                }
                out.push(']');
            }
            out.push_str(&format!("], \"resolved_by_impulse\": {}", p.resolved_by_impulse));
        }
        out.push('}');
    }
    out.push(']');
    out
}

#[cfg(test)]
mod tests {
    use super::super::PainleveRecord;
    use super::*;

    fn event(kind: &'static str) -> EventRecord {
        EventRecord {
            t: 0.25,
            contact: "foot".into(),
            point: 2,
            kind,
            impulse: [1.5, -0.5, 0.0],
            energy: 0.125,
            u_before: vec![],
            u_after: vec![],
            painleve: None,
            steps: 3,
        }
    }

    #[test]
    fn no_events_is_an_empty_list() {
        assert_eq!(events_json(&[]), "[]");
    }

    #[test]
    fn an_impact_carries_the_velocities_and_keys_in_order() {
        let mut e = event("impact");
        e.u_before = vec![-2.0, 0.5];
        e.u_after = vec![1.0, 0.5];
        let want = concat!(
            r#"[{"t": 0.25, "contact": "foot", "point": 2, "event": "impact", "impulse_n": 1.5, "#,
            r#""impulse_t": [-0.5, 0.0], "energy": 0.125, "steps": 3, "u_before": [-2.0, 0.5], "#,
            r#""u_after": [1.0, 0.5]}]"#
        );
        assert_eq!(events_json(&[e]), want);
    }

    #[test]
    fn non_finite_numbers_and_quotes_are_written_as_python_reads_them() {
        // a quote in a name must be escaped; NaN and ±Infinity as Python's json module writes them
        let mut a = event("painleve");
        a.contact = "rod \"A\"".into();
        a.energy = f64::NAN;
        a.impulse = [f64::INFINITY, f64::NEG_INFINITY, 0.5];
        a.painleve = Some(PainleveRecord {
            mu: 0.5,
            mu_critical: f64::INFINITY,
            non_unique: true,
            solutions: [vec!["rod[0]".into()], vec!["rod[0]".into(), "rod[1]".into()]],
            resolved_by_impulse: false,
        });
        let b = event("slip");
        let want = concat!(
            r#"[{"t": 0.25, "contact": "rod \"A\"", "point": 2, "event": "painleve", "impulse_n": Infinity, "#,
            r#""impulse_t": [-Infinity, 0.5], "energy": NaN, "steps": 3, "mu": 0.5, "mu_critical": Infinity, "#,
            r#""situation": "non-unique", "solutions": [["rod[0]"], ["rod[0]", "rod[1]"]], "#,
            r#""resolved_by_impulse": false}, "#,
            r#"{"t": 0.25, "contact": "foot", "point": 2, "event": "slip", "impulse_n": 1.5, "#,
            r#""impulse_t": [-0.5, 0.0], "energy": 0.125, "steps": 3}]"#
        );
        assert_eq!(events_json(&[a, b]), want);
    }
}
