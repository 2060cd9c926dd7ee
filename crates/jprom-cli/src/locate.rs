//! Where a key is in a TOML study file, for error messages that give the line of a value
//! found wrong after parsing (the JSON side is the core's `jprom::io::locate`).

use jprom::io::locate::{line_of, Step};

/// 1-based line of the deepest step of `path` found in the TOML `text`.
pub fn toml_line(text: &str, path: &[Step]) -> Option<usize> {
    let table = toml::de::DeTable::parse(text).ok()?;
    let mut found: Option<std::ops::Range<usize>> = None;
    let mut at: Option<&toml::de::DeValue> = None;
    let root = table.get_ref();
    for (k, step) in path.iter().enumerate() {
        let next = match (step, at) {
            (Step::Key(key), None) if k == 0 => root.iter().find(|(name, _)| name.get_ref().as_ref() == key.as_str()).map(|(n, v)| (n.span(), v)),
            (Step::Key(key), Some(toml::de::DeValue::Table(t))) => {
                t.iter().find(|(name, _)| name.get_ref().as_ref() == key.as_str()).map(|(n, v)| (n.span(), v))
            }
            (Step::Index(i), Some(toml::de::DeValue::Array(a))) => a.get(*i).map(|v| (v.span(), v)),
            _ => None,
        };
        let Some((span, value)) = next else { break };
        found = Some(span);
        at = Some(value.get_ref());
    }
    found.map(|span| line_of(text, span.start))
}


#[cfg(test)]
mod tests {
    use super::*;
    use jprom::io::locate::key_path;

    #[test]
    fn toml_keys_are_found_on_their_line() {
        let text = "[model]\nkind = \"blade\"\n\n[band]\nhz_start = 1.0\npoints = 5\n[[forcing.harmonic]]\nnodes = [1]\n[[forcing.harmonic]]\nnodes = [2]\n";
        assert_eq!(toml_line(text, &key_path("band.points")), Some(6));
        assert_eq!(toml_line(text, &key_path("forcing.harmonic[1].nodes")), Some(10));
        assert_eq!(toml_line(text, &key_path("band.nothing")), Some(4));
    }
}
