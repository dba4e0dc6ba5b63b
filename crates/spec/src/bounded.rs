//! Reading an input file of bounded size: a regular file only (a FIFO or a device such as
//! `/dev/zero` would block or never end), and at most `limit` bytes, counted while reading
//! (the size on disk can change or, through a symlink, not be known beforehand).

use std::io::Read;
use std::path::Path;

/// Why a file could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// Not a regular file (a folder, FIFO, socket or device).
    #[error("{path}: not a regular file")]
    NotRegular {
        /// The file.
        path: String,
    },
    /// Larger than the limit.
    #[error("{path}: larger than {limit} bytes")]
    TooLarge {
        /// The file.
        path: String,
        /// The limit (bytes).
        limit: u64,
    },
    /// Not UTF-8 text.
    #[error("{path}: not UTF-8 text")]
    NotText {
        /// The file.
        path: String,
    },
    /// The operating system refused.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What the system said.
        message: String,
    },
}

/// The bytes of the regular file `path` (symlinks followed), at most `limit` of them.
pub fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    let shown = || path.display().to_string();
    let io = |e: std::io::Error| ReadError::Io {
        path: shown(),
        message: e.to_string(),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(ReadError::NotRegular { path: shown() });
    }
    if meta.len() > limit {
        return Err(ReadError::TooLarge {
            path: shown(),
            limit,
        });
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(ReadError::TooLarge {
            path: shown(),
            limit,
        });
    }
    Ok(bytes)
}

/// The UTF-8 text of the regular file `path`, at most `limit` bytes.
pub fn read_text_bounded(path: &Path, limit: u64) -> Result<String, ReadError> {
    String::from_utf8(read_bounded(path, limit)?).map_err(|_| ReadError::NotText {
        path: path.display().to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_is_not_a_regular_file_or_too_large() {
        let dir = std::env::temp_dir().join(format!("bounded-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap_or_default();
        let f = dir.join("a.toml");
        std::fs::write(&f, "x = 1\n").unwrap_or_default();
        assert_eq!(read_text_bounded(&f, 100), Ok("x = 1\n".to_owned()));
        assert!(matches!(
            read_bounded(&f, 3),
            Err(ReadError::TooLarge { limit: 3, .. })
        ));
        assert!(matches!(
            read_bounded(&dir, 100),
            Err(ReadError::NotRegular { .. })
        ));
        if Path::new("/dev/zero").exists() {
            assert!(matches!(
                read_bounded(Path::new("/dev/zero"), 100),
                Err(ReadError::NotRegular { .. })
            ));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
