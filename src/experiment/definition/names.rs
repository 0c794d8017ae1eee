//! Names that become paths and script words: experiment, curve and sweep-point names.
//!
//! A name is used as one directory below the results root and as a word in a Slurm script, so it
//! must be one safe path component made of plain characters: no separator, no `..`, nothing
//! absolute, no whitespace or control characters. Checking here, before any file is touched, is
//! what keeps every write and every `--force` deletion inside `--out`.

/// Longest name accepted (a path component is at most 255 bytes on common file systems).
pub const MAX_NAME_BYTES: usize = 200;

/// Why a name cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NameError {
    /// An empty name.
    #[error("{kind} name is empty")]
    Empty {
        /// What the name names (e.g. `experiment`).
        kind: &'static str,
    },
    /// A name beyond [`MAX_NAME_BYTES`].
    #[error("{kind} name {name:?} is {len} bytes long, at most {MAX_NAME_BYTES} allowed")]
    TooLong {
        /// What the name names.
        kind: &'static str,
        /// The name given.
        name: String,
        /// Its length in bytes.
        len: usize,
    },
    /// A character outside the allowed set.
    #[error("{kind} name {name:?} contains {found:?}: names are one path component of letters, digits and {allowed}")]
    BadChar {
        /// What the name names.
        kind: &'static str,
        /// The name given.
        name: String,
        /// The first character refused.
        found: char,
        /// The punctuation allowed besides letters and digits, in words.
        allowed: &'static str,
    },
    /// A name starting with `.` or `-` (hidden file, or read as a flag).
    #[error("{kind} name {name:?} must not start with `.` or `-`")]
    BadStart {
        /// What the name names.
        kind: &'static str,
        /// The name given.
        name: String,
    },
}

/// Punctuation allowed in an experiment name (a plain identifier).
const IDENT_PUNCT: &str = "_-.";
/// Punctuation allowed in a curve name: `<method>@key=value,key=value` with numbers like `1e-3`.
const CURVE_PUNCT: &str = "_-.@=,+";

fn check(kind: &'static str, name: &str, punct: &'static str) -> Result<(), NameError> {
    if name.is_empty() {
        return Err(NameError::Empty { kind });
    }
    if name.len() > MAX_NAME_BYTES {
        return Err(NameError::TooLong {
            kind,
            name: name.chars().take(40).collect::<String>() + "...",
            len: name.len(),
        });
    }
    if let Some(found) = name
        .chars()
        .find(|&c| !(c.is_ascii_alphanumeric() || punct.contains(c)))
    {
        return Err(NameError::BadChar {
            kind,
            name: name.to_string(),
            found,
            allowed: if punct == IDENT_PUNCT {
                "`_ - .`"
            } else {
                "`_ - . @ = , +`"
            },
        });
    }
    // A leading `.` covers `.`, `..` and hidden names; a leading `-` would read as a flag.
    if name.starts_with('.') || name.starts_with('-') {
        return Err(NameError::BadStart {
            kind,
            name: name.to_string(),
        });
    }
    Ok(())
}

/// Check an experiment name: a plain identifier (letters, digits, `_`, `-`, `.`).
pub fn check_experiment_name(name: &str) -> Result<(), NameError> {
    check("experiment", name, IDENT_PUNCT)
}

/// Check a curve name (`<method>` or `<method>@<sweep point>`), one directory of the results tree.
pub fn check_curve_name(name: &str) -> Result<(), NameError> {
    check("curve", name, CURVE_PUNCT)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Component, Path};

    #[test]
    fn plain_names_pass() {
        for n in ["fig4a_bp10", "quickstart-bp10", "v1.2", "A9"] {
            check_experiment_name(n).unwrap();
        }
        for n in ["our1", "our1@l_rate=0.001,trace_len=10", "our1@l_rate=1e-5"] {
            check_curve_name(n).unwrap();
        }
    }

    #[test]
    fn every_accepted_name_is_exactly_one_normal_path_component() {
        // Every short string over an alphabet of dangerous and plain characters: whatever passes
        // must be a single normal component, so joining it to a root stays below that root.
        let alphabet = [
            'a', '.', '/', '\\', '\n', ' ', '-', '@', '$', '\0', '~', 'é',
        ];
        let mut words = vec![String::new()];
        let mut last = words.clone();
        for _ in 0..3 {
            last = last
                .iter()
                .flat_map(|w| alphabet.iter().map(move |c| format!("{w}{c}")))
                .collect();
            words.extend(last.iter().cloned());
        }
        let mut tried = 0;
        for w in &words {
            tried += 1;
            for ok in [
                check_experiment_name(w).is_ok(),
                check_curve_name(w).is_ok(),
            ] {
                if ok {
                    let comps: Vec<_> = Path::new(w).components().collect();
                    assert_eq!(comps.len(), 1, "{w:?}");
                    assert!(matches!(comps[0], Component::Normal(_)), "{w:?}");
                    assert!(w.chars().all(|c| c.is_ascii_graphic()), "{w:?}");
                }
            }
        }
        assert!(tried > 1000);
    }

    #[test]
    fn hostile_names_are_refused_with_the_reason() {
        for (n, why) in [
            ("", "empty"),
            ("..", "start with"),
            (".", "start with"),
            ("../../x", "contains '/'"),
            ("/etc", "contains '/'"),
            ("a\nb", "contains '\\n'"),
            ("a b", "contains ' '"),
            ("-rf", "start with"),
            ("$(id)", "contains '$'"),
        ] {
            let e = check_experiment_name(n).unwrap_err().to_string();
            assert!(e.contains(why), "{n:?}: {e}");
        }
        let long = "x".repeat(MAX_NAME_BYTES + 1);
        assert!(matches!(
            check_curve_name(&long),
            Err(NameError::TooLong { .. })
        ));
    }
}
