//! How the binary says an error: the main command's message and a batch's failed clip.

/// The error and its causes joined by `: `, each text once (the main command's message, a
/// batch's failed clip). Library errors often say their cause in their own message too
/// (`{path}: {source}`), and `{err:#}` would then print a path twice or an OS error three
/// times; a cause already said is left out, and a context that its cause repeats in full
/// (`missing.bvh` then `missing.bvh: No such file`) gives way to it.
pub fn error_chain(err: &anyhow::Error) -> String {
    let mut parts: Vec<String> = Vec::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if text.is_empty() || parts.iter().any(|p| p.contains(&text)) {
            continue;
        }
        match parts.last_mut() {
            Some(last) if text.starts_with(&format!("{last}: ")) => *last = text,
            _ => parts.push(text),
        }
    }
    parts.join(": ")
}

#[cfg(test)]
mod tests {
    use super::error_chain;
    use anyhow::Context;

    fn io() -> std::io::Error {
        std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory (os error 2)")
    }

    #[test]
    fn causes_are_said_once() {
        // A library error that repeats its source, wrapped in a context that names the file.
        #[derive(Debug)]
        struct Wrapped {
            source: std::io::Error,
        }
        impl std::fmt::Display for Wrapped {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "nope.json: cannot read file: {}", self.source)
            }
        }
        impl std::error::Error for Wrapped {
            fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
                Some(&self.source)
            }
        }
        let err: anyhow::Error = Wrapped { source: io() }.into();
        assert_eq!(
            error_chain(&err),
            "nope.json: cannot read file: No such file or directory (os error 2)"
        );
        // A context that its cause repeats: said once.
        let inner: anyhow::Error =
            anyhow::anyhow!("missing.bvh: No such file or directory (os error 2)");
        let err = inner.context("missing.bvh");
        assert_eq!(error_chain(&err), "missing.bvh: No such file or directory (os error 2)");
        // Distinct levels are all kept.
        let err = Err::<(), _>(io()).context("walk.bvh").context("retargeting").unwrap_err();
        assert_eq!(
            error_chain(&err),
            "retargeting: walk.bvh: No such file or directory (os error 2)"
        );
    }
}
