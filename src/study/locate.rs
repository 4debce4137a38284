//! Where a study file's error is: the key as written in the file and its line.
//!
//! A problem's own validation names its inputs as the solver calls them (`half_width`,
//! `element_size`); a study file writes them under a section or a sweep (`block.half_width`,
//! `sweeps[0].element_sizes`). [`locate`] turns such an error ([`StudyError::CaseInput`]) into
//! one naming the file's key, and adds the line of the key (or of the deepest section of it
//! that the file has) to every [`StudyError::Invalid`], so that a user can go straight to it.

use super::StudyError;
use toml_edit::{ImDocument, Item};

/// One step of a key path: a table key or an array index.
#[derive(Debug, Clone, PartialEq)]
enum Step<'a> {
    Key(&'a str),
    Index(usize),
}

/// `sweeps[0].quick.element_sizes[2]` as steps; `None` if it is not a key path (e.g. it holds
/// spaces).
fn steps(path: &str) -> Option<Vec<Step<'_>>> {
    let mut out = vec![];
    for part in path.split('.') {
        let (name, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if name.is_empty()
            || !name
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
        {
            return None;
        }
        out.push(Step::Key(name));
        while let Some(r) = rest.strip_prefix('[') {
            let close = r.find(']')?;
            out.push(Step::Index(r[..close].parse().ok()?));
            rest = &r[close + 1..];
        }
        if !rest.is_empty() {
            return None;
        }
    }
    Some(out)
}

/// Whether the file has `path`, and the byte span of the deepest step of it found (the whole
/// path's if it has it).
fn walk(doc: &ImDocument<&str>, path: &[Step<'_>]) -> (bool, Option<std::ops::Range<usize>>) {
    // Where the walk is: an item, or a table of an array of tables (not an item of its own).
    enum At<'d> {
        Item(&'d Item),
        Table(&'d toml_edit::Table),
    }
    let mut at = At::Item(doc.as_item());
    let mut span = None;
    for (n, step) in path.iter().enumerate() {
        let table = match &at {
            At::Item(i) => i.as_table_like(),
            At::Table(t) => Some(*t as &dyn toml_edit::TableLike),
        };
        at = match (step, &at) {
            (Step::Key(k), _) => match table.and_then(|t| t.get_key_value(k)) {
                Some((key, v)) => {
                    span = key.span().or_else(|| v.span()).or(span);
                    At::Item(v)
                }
                None => return (false, span),
            },
            (Step::Index(i), At::Item(Item::ArrayOfTables(a))) => match a.get(*i) {
                Some(t) => {
                    span = t.span().or(span);
                    At::Table(t)
                }
                None => return (false, span),
            },
            // An element of an array value is the last step a key path can take.
            (Step::Index(i), At::Item(Item::Value(toml_edit::Value::Array(a)))) => {
                let v = a.get(*i);
                if let Some(s) = v.and_then(|v| v.span()) {
                    span = Some(s);
                }
                return (v.is_some() && n + 1 == path.len(), span);
            }
            _ => return (false, span),
        };
    }
    (true, span)
}

fn line_at(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The line of `key` in `text`, or of the deepest section of it that the file has; `None`
/// if the text does not parse or the key is not a path.
pub fn line_of(text: &str, key: &str) -> Option<usize> {
    line_in(&ImDocument::parse(text).ok()?, key)
}

/// [`line_of`] in the parsed document.
fn line_in(doc: &ImDocument<&str>, key: &str) -> Option<usize> {
    let (_, span) = walk(doc, &steps(key)?);
    span.map(|s| line_at(doc.raw(), s.start))
}

/// Does the file have `key`?
fn has(doc: &ImDocument<&str>, key: &str) -> bool {
    steps(key).is_some_and(|p| walk(doc, &p).0)
}

/// The file's key of a problem input named `field` (`half_width`, `newton.tolerance`,
/// `ghost.gamma`), looked for in `scope` (e.g. `sweeps[0].quick`), then in each scope above
/// it, then in the file's sections in file order; as the singular and as the plural of a
/// swept list (`element_size` → `element_sizes`). `None` if the file has no such key.
fn resolve(doc: &ImDocument<&str>, scope: &str, field: &str) -> Option<String> {
    // A problem may prefix its own section's name (`dynamics.beta`, the bar's `[bar] beta`):
    // the field, then its tails.
    let mut tail = field;
    loop {
        if let Some(k) = resolve_exact(doc, scope, tail) {
            return Some(k);
        }
        tail = &tail[tail.find('.')? + 1..];
    }
}

fn resolve_exact(doc: &ImDocument<&str>, scope: &str, field: &str) -> Option<String> {
    let head_end = field.find(['.', '[']).unwrap_or(field.len());
    let (head, rest) = field.split_at(head_end);
    let names = [format!("{head}{rest}"), format!("{head}s{rest}")];
    // `sweeps[0].quick`, `sweeps[0]`, the top level, then each section of the file.
    let scopes = std::iter::successors(Some(scope), |s| s.rfind('.').map(|i| &s[..i]))
        .filter(|s| !s.is_empty())
        .chain([""])
        .map(str::to_string);
    let sections = doc
        .as_table()
        .iter()
        .filter(|(_, item)| item.is_table_like())
        .map(|(section, _)| section.to_string());
    scopes.chain(sections).find_map(|scope| {
        names.iter().find_map(|n| {
            let key = if scope.is_empty() {
                n.clone()
            } else {
                format!("{scope}.{n}")
            };
            has(doc, &key).then_some(key)
        })
    })
}

/// `err` with the key as the file writes it ([`StudyError::CaseInput`] resolved) and the line
/// of the key appended to the file name (`studies/x.toml:12`).
pub fn locate(text: &str, err: StudyError) -> StudyError {
    let doc = ImDocument::parse(text).ok();
    let (file, key, value, allowed) = match err {
        StudyError::CaseInput(c) => {
            let super::CaseInput {
                file,
                scope,
                case,
                field,
                value,
                allowed,
            } = *c;
            let key = doc
                .as_ref()
                .and_then(|d| resolve(d, &scope, &field))
                .unwrap_or(field);
            (file, key, value, format!("{allowed} (in case {case})"))
        }
        StudyError::Invalid {
            file,
            key,
            value,
            allowed,
        } => (file, key, value, allowed),
        other => return other,
    };
    let file = match doc.as_ref().and_then(|d| line_in(d, &key)) {
        Some(line) => format!("{file}:{line}"),
        None => file,
    };
    StudyError::Invalid {
        file,
        key,
        value,
        allowed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "name = \"x\"\n\n[block]\nhalf_width = 4.0\n\n[[sweeps]]\nid = \"a\"\nelement_sizes = [1.0, 0.5]\n\n[sweeps.quick]\nelement_sizes = [1.0]\n\n[[sweeps]]\nid = \"b\"\nyield_stress = 2.0\n";

    #[test]
    fn lines_of_keys_sections_and_array_elements() {
        assert_eq!(line_of(TEXT, "name"), Some(1));
        assert_eq!(line_of(TEXT, "block.half_width"), Some(4));
        assert_eq!(line_of(TEXT, "block"), Some(3));
        assert_eq!(line_of(TEXT, "sweeps[0].element_sizes"), Some(8));
        assert_eq!(line_of(TEXT, "sweeps[0].element_sizes[1]"), Some(8));
        assert_eq!(line_of(TEXT, "sweeps[0].quick.element_sizes"), Some(11));
        assert_eq!(line_of(TEXT, "sweeps[1].yield_stress"), Some(15));
        // The deepest section the file has.
        assert_eq!(line_of(TEXT, "block.height"), Some(3));
        assert_eq!(line_of(TEXT, "sweeps[0] case x"), None);
    }

    #[test]
    fn problem_inputs_resolve_to_the_files_keys() {
        let doc = ImDocument::parse(TEXT).unwrap();
        assert_eq!(
            resolve(&doc, "sweeps[0]", "half_width").as_deref(),
            Some("block.half_width")
        );
        assert_eq!(
            resolve(&doc, "sweeps[0].quick", "element_size").as_deref(),
            Some("sweeps[0].quick.element_sizes")
        );
        assert_eq!(
            resolve(&doc, "sweeps[0]", "element_size").as_deref(),
            Some("sweeps[0].element_sizes")
        );
        assert_eq!(
            resolve(&doc, "sweeps[1]", "yield_stress").as_deref(),
            Some("sweeps[1].yield_stress")
        );
        assert_eq!(resolve(&doc, "sweeps[0]", "poisson_ratio"), None);
    }

    #[test]
    fn a_case_input_error_names_the_key_and_its_line() {
        let e = locate(
            TEXT,
            StudyError::CaseInput(Box::new(crate::study::CaseInput {
                file: "s.toml".into(),
                scope: "sweeps[0]".into(),
                case: "igimp-h1".into(),
                field: "half_width".into(),
                value: "-4".into(),
                allowed: "must be > 0".into(),
            })),
        );
        assert_eq!(
            e.to_string(),
            "s.toml:4: invalid `block.half_width` = -4: must be > 0 (in case igimp-h1)"
        );
    }
}
