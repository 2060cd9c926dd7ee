//! Where a key is in a JSON text (the CLI adds TOML), for error messages that give the line of a value
//! found wrong after parsing (a study's range check, an inconsistent size in a loaded file,
//! an unknown key). Keys are written as in the messages: `band.points`,
//! `model.contacts[1].normal`, `data.points[3].outputs`.

/// One step of a key path: a table/object key or an array index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Step {
    Key(String),
    Index(usize),
}

/// Splits `a.b[2].c` into steps (`[Key a, Key b, Index 2, Key c]`).
pub fn key_path(key: &str) -> Vec<Step> {
    let mut steps = Vec::new();
    for part in key.split('.').filter(|p| !p.is_empty()) {
        let mut rest = part;
        if let Some(i) = rest.find('[') {
            if i > 0 {
                steps.push(Step::Key(rest[..i].to_string()));
            }
            rest = &rest[i..];
            while let Some(stripped) = rest.strip_prefix('[') {
                let Some(end) = stripped.find(']') else { break };
                match stripped[..end].parse() {
                    Ok(n) => steps.push(Step::Index(n)),
                    Err(_) => steps.push(Step::Key(stripped[..end].to_string())),
                }
                rest = &stripped[end + 1..];
            }
        } else if let Ok(n) = rest.parse::<usize>() {
            // serde_ignored writes indices as path components: `points.3.x`
            steps.push(Step::Index(n));
        } else {
            steps.push(Step::Key(rest.to_string()));
        }
    }
    steps
}

/// Formats steps back as `a.b[2].c`.
pub fn key_text(steps: &[Step]) -> String {
    let mut s = String::new();
    for st in steps {
        match st {
            Step::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Step::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// 1-based line of the deepest step of `path` found in the JSON `text` (the key itself, or
/// the array element); `None` if not even the first step is there.
pub fn json_line(text: &str, path: &[Step]) -> Option<usize> {
    let mut s = Scanner { b: text.as_bytes(), i: 0, line: 1 };
    s.find(path, None)
}

/// 1-based line of byte `offset`.
pub fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end].iter().filter(|&&c| c == b'\n').count() + 1
}

/// A forgiving JSON walker: it only needs to skip values and read keys.
struct Scanner<'a> {
    b: &'a [u8],
    i: usize,
    line: usize,
}

impl Scanner<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn bump(&mut self) -> Option<u8> {
        let c = self.peek()?;
        self.i += 1;
        if c == b'\n' {
            self.line += 1;
        }
        Some(c)
    }

    fn ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\r' | b'\n')) {
            self.bump();
        }
    }

    /// A string's raw content (escapes kept, which is enough to compare plain keys).
    fn string(&mut self) -> Option<String> {
        if self.bump()? != b'"' {
            return None;
        }
        let start = self.i;
        loop {
            match self.bump()? {
                b'"' => return Some(String::from_utf8_lossy(&self.b[start..self.i - 1]).into_owned()),
                b'\\' => {
                    self.bump()?;
                }
                _ => {}
            }
        }
    }

    fn skip_value(&mut self) -> Option<()> {
        self.ws();
        match self.peek()? {
            b'"' => self.string().map(|_| ()),
            open @ (b'{' | b'[') => {
                let close = if open == b'{' { b'}' } else { b']' };
                self.bump();
                loop {
                    self.ws();
                    match self.peek()? {
                        c if c == close => {
                            self.bump();
                            return Some(());
                        }
                        b',' | b':' => {
                            self.bump();
                        }
                        _ => self.skip_value()?,
                    }
                }
            }
            _ => {
                while !matches!(self.peek(), None | Some(b',' | b'}' | b']' | b' ' | b'\t' | b'\r' | b'\n')) {
                    self.bump();
                }
                Some(())
            }
        }
    }

    /// At a value: the line of the deepest step of `path` reached (`best` so far).
    fn find(&mut self, path: &[Step], best: Option<usize>) -> Option<usize> {
        self.ws();
        let Some(step) = path.first() else { return best };
        match (step, self.peek()) {
            (Step::Key(key), Some(b'{')) => {
                self.bump();
                loop {
                    self.ws();
                    match self.peek() {
                        Some(b'"') => {}
                        Some(b',') => {
                            self.bump();
                            continue;
                        }
                        _ => return best,
                    }
                    let line = self.line;
                    let name = self.string()?;
                    self.ws();
                    if self.bump()? != b':' {
                        return best;
                    }
                    if &name == key {
                        return self.find(&path[1..], Some(line));
                    }
                    self.skip_value()?;
                }
            }
            (Step::Index(n), Some(b'[')) => {
                self.bump();
                let mut k = 0;
                loop {
                    self.ws();
                    match self.peek() {
                        Some(b']') | None => return best,
                        Some(b',') => {
                            self.bump();
                            continue;
                        }
                        _ => {}
                    }
                    if k == *n {
                        let line = self.line;
                        return self.find(&path[1..], Some(line));
                    }
                    self.skip_value()?;
                    k += 1;
                }
            }
            _ => best,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_paths_round_trip() {
        let p = key_path("model.contacts[1].normal");
        assert_eq!(p, vec![Step::Key("model".into()), Step::Key("contacts".into()), Step::Index(1), Step::Key("normal".into())]);
        assert_eq!(key_text(&p), "model.contacts[1].normal");
        assert_eq!(key_path("data.points.3.z"), key_path("data.points[3].z"));
    }

    #[test]
    fn json_keys_are_found_on_their_line() {
        let text = "{\n  \"a\": {\"x\": [1,\n 2, {\"y\": 3}]},\n  \"band\": {\n    \"points\": 7\n  }\n}";
        assert_eq!(json_line(text, &key_path("band.points")), Some(5));
        assert_eq!(json_line(text, &key_path("a.x[2].y")), Some(3));
        assert_eq!(json_line(text, &key_path("band.missing")), Some(4), "falls back on the parent");
        assert_eq!(json_line(text, &key_path("nothing")), None);
    }

}
