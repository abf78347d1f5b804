//! Reading the text files a user points the toolkit at (scenario TOML, MATLAB `.fis`) with a
//! size limit, so that a huge file is a clear error rather than memory exhaustion, and only if it
//! is a regular file, so that a FIFO, `/dev/zero` or a socket is a clear error rather than a
//! hang. (Sweep shard files are read a line at a time, each line with
//! its own limit: `study::ShardReader`.)

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// Largest scenario or `.fis` file read (16 MiB, the limit of an `hrm eval` request line): a
/// thousand times the largest real file.
pub const MAX_INPUT_FILE_BYTES: u64 = 16 << 20;

/// Reads the UTF-8 regular file at `path` ([`open_regular_file`]), refusing one of more than
/// `max_bytes` bytes: by its size before anything is read, and after `max_bytes + 1` bytes if
/// it grows while being read. The
/// errors' kinds are `FileTooLarge` and `InvalidData` (not UTF-8); their messages leave naming
/// the file to the caller.
///
/// ```
/// let path = std::env::temp_dir().join(format!("input-file-doc-{}.txt", std::process::id()));
/// std::fs::write(&path, "twelve bytes")?;
/// assert_eq!(sim_core::read_text_file(&path, 12)?, "twelve bytes");
/// let err = sim_core::read_text_file(&path, 11).unwrap_err();
/// assert_eq!(err.to_string(), "the file has 12 bytes, more than the 11 allowed");
/// # std::fs::remove_file(&path)?;
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn read_text_file(path: &Path, max_bytes: u64) -> std::io::Result<String> {
    let file = open_regular_file(path)?;
    let metadata = file.metadata()?;
    if metadata.is_file() && metadata.len() > max_bytes {
        return Err(too_large(format!(
            "the file has {} bytes, more than the {max_bytes} allowed",
            metadata.len()
        )));
    }
    let mut bytes = Vec::new();
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(format!(
            "the file holds more than the {max_bytes} bytes allowed"
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        Error::new(
            ErrorKind::InvalidData,
            format!(
                "the file is not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// Opens the file at `path` for reading if it is a regular file (symbolic links followed),
/// checked before it is opened: opening a FIFO would wait for a writer forever, and a device
/// or socket is no input file. The error kinds are `IsADirectory` and `InvalidInput`.
pub fn open_regular_file(path: &Path) -> std::io::Result<std::fs::File> {
    let metadata = std::fs::metadata(path)?;
    if metadata.is_dir() {
        return Err(Error::new(
            ErrorKind::IsADirectory,
            "is a directory, not a file",
        ));
    }
    if !metadata.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            "is not a regular file (a FIFO, socket or device): only regular files are read",
        ));
    }
    std::fs::File::open(path)
}

fn too_large(message: String) -> Error {
    Error::new(ErrorKind::FileTooLarge, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_sizes_streams_and_encodings() {
        let dir = std::env::temp_dir().join(format!("sim-core-input-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("f.txt");
        std::fs::write(&path, "abc").unwrap();
        assert_eq!(read_text_file(&path, 3).unwrap(), "abc");
        let err = read_text_file(&path, 2).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::FileTooLarge);
        std::fs::write(&path, b"a\xffb").unwrap();
        let err = read_text_file(&path, 10).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::InvalidData);
        assert!(err.to_string().contains("offset 1"), "{err}");
        assert_eq!(
            read_text_file(&dir, 10).unwrap_err().kind(),
            ErrorKind::IsADirectory
        );
        // A device or a FIFO is refused before it is opened (a FIFO would block the open).
        if Path::new("/dev/zero").exists() {
            let err = read_text_file(Path::new("/dev/zero"), 1 << 16).unwrap_err();
            assert_eq!(err.kind(), ErrorKind::InvalidInput);
            assert!(err.to_string().contains("not a regular file"), "{err}");
        }
        let fifo = dir.join("fifo.fis");
        if std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success())
        {
            let err = read_text_file(&fifo, 10).unwrap_err();
            assert_eq!(err.kind(), ErrorKind::InvalidInput);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
