//! Files and standard input (`-`) read by the commands, bounded in size while reading: a
//! device such as `/dev/zero` or an endless pipe ends with an error at the limit instead of
//! filling memory.

use anyhow::{anyhow, Context as _, Result};
use std::io::Read;
use std::path::Path;

/// Largest script, listing or image list read (bytes).
pub const MAX_TEXT: u64 = 4 << 20;

/// Largest serial stream decoded (bytes).
pub const MAX_STREAM: u64 = 64 << 20;

/// The bytes of `path` (`-`: standard input), at most `limit` of them.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>> {
    let name = if path == Path::new("-") {
        "standard input".to_owned()
    } else {
        path.display().to_string()
    };
    let reader: Box<dyn Read> = if path == Path::new("-") {
        Box::new(std::io::stdin())
    } else {
        let f = std::fs::File::open(path).with_context(|| format!("cannot read {name}"))?;
        if f.metadata().is_ok_and(|m| m.is_dir()) {
            return Err(anyhow!("cannot read {name}: a folder"));
        }
        Box::new(f)
    };
    let mut bytes = Vec::new();
    reader
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .with_context(|| format!("cannot read {name}"))?;
    if bytes.len() as u64 > limit {
        return Err(anyhow!("cannot read {name}: larger than {limit} bytes"));
    }
    Ok(bytes)
}

/// The UTF-8 text of `path` (`-`: standard input), at most `limit` bytes.
pub fn read_text(path: &Path, limit: u64) -> Result<String> {
    String::from_utf8(read_bytes(path, limit)?)
        .map_err(|_| anyhow!("cannot read {}: not UTF-8 text", path.display()))
}
