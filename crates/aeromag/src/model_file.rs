//! Reading and writing model files of every kind (Tolles-Lawson, rotor,
//! pod): JSON, versioned (`spec/data-formats.md`, "Model files").

use crate::error::{Error, Result};
use aeromag_compensation::model_file::TlModel;
use aeromag_compensation::pod::model_file::PodModelFile;
use aeromag_compensation::rotor::model_file::RotorModelFile;
use std::io::Write;
use std::path::Path;

/// A model that is stored as a JSON model file.
///
/// ```no_run
/// use aeromag::{ModelFile, TlModel};
/// let model = TlModel::read("model.json")?;
/// model.write("copy.json")?;
/// # Ok::<(), aeromag::Error>(())
/// ```
pub trait ModelFile: Sized {
    /// Parse and check a model file's text; `origin` names it in errors.
    fn parse(text: &str, origin: &str) -> Result<Self>;

    /// The model file's text (pretty JSON).
    fn json(&self) -> Result<String>;

    /// Read and check a model file (bad input when it cannot be read or is
    /// not a model of this kind).
    fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = read_text_file(path)?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Write the model file: to a temporary file in the same folder,
    /// renamed when complete, so an interrupted write never leaves a
    /// complete-looking partial file.
    fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomically(path.as_ref(), self.json()?.as_bytes())
    }
}

/// The largest model, settings or scenario file read, bytes (64 MiB): the
/// largest model files are tens of kilobytes. Found by fuzzing:
/// `--model /dev/zero` grew to a gigabyte before running out of memory.
pub const MAX_TEXT_FILE_BYTES: u64 = 64 << 20;

/// The text of a model, settings, scenario, EM system or EM calibration
/// file, without a leading UTF-8 byte-order mark (editors on Windows write
/// one; the CSV reader skips it too, and serde_json refused it: "expected
/// value at line 1 column 1"): bad input when it cannot be read, is not
/// UTF-8 or is larger than [`MAX_TEXT_FILE_BYTES`].
pub fn read_text_file(path: &Path) -> Result<String> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(|e| Error::read(path, e))?;
    let mut text = String::new();
    file.take(MAX_TEXT_FILE_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| Error::read(path, e))?;
    if text.len() as u64 > MAX_TEXT_FILE_BYTES {
        return Err(Error::bad_file(
            path.display().to_string(),
            format!(
                "larger than {} MiB: not a model, settings or scenario file",
                MAX_TEXT_FILE_BYTES >> 20
            ),
        ));
    }
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// The `kind` of the model file at `path` (`tolles-lawson`,
/// `tolles-lawson-sensors`, `rotor`, …), to choose how to read it; bad
/// input when it cannot be read or is not a model file.
pub fn kind_of(path: impl AsRef<Path>) -> Result<String> {
    let path = path.as_ref();
    let text = read_text_file(path)?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::json(path.display().to_string(), "not a JSON model file", &e))?;
    match v.get("kind").and_then(|k| k.as_str()) {
        Some(k) => Ok(k.to_string()),
        None => Err(Error::bad_file(
            path.display().to_string(),
            "no \"kind\" key; not an aeromag model file",
        )),
    }
}

impl ModelFile for TlModel {
    fn parse(text: &str, origin: &str) -> Result<Self> {
        Ok(TlModel::from_json(text, origin)?)
    }
    fn json(&self) -> Result<String> {
        Ok(self.to_json()?)
    }
}

impl ModelFile for aeromag_compensation::model_file::SensorsModel {
    fn parse(text: &str, origin: &str) -> Result<Self> {
        Ok(Self::from_json(text, origin)?)
    }
    fn json(&self) -> Result<String> {
        Ok(self.to_json()?)
    }
}

impl ModelFile for RotorModelFile {
    fn parse(text: &str, origin: &str) -> Result<Self> {
        Ok(RotorModelFile::from_json(text, origin)?)
    }
    fn json(&self) -> Result<String> {
        Ok(serde_json::to_string_pretty(self)?)
    }
}

impl ModelFile for PodModelFile {
    fn parse(text: &str, origin: &str) -> Result<Self> {
        Ok(PodModelFile::from_json(text, origin)?)
    }
    fn json(&self) -> Result<String> {
        Ok(serde_json::to_string_pretty(self)?)
    }
}

/// Create the output folder `out` (and its parents) for a set of files.
/// An empty path is bad input: `simulate_em("")` from Python wrote its
/// five files into the current folder without a word (the CLI's
/// `--out ''` is refused by its parser); `.` names the current folder.
pub fn create_output_folder(out: &Path) -> Result<()> {
    if out.as_os_str().is_empty() {
        return Err(Error::bad_input(
            "the output folder is empty: name a folder ('.' for the current one)",
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| Error::write(out, e))
}

/// Write `bytes` to `path` through a temporary file in the same folder,
/// renamed when complete.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write_streamed(path, |w| {
        w.write_all(bytes).map_err(|e| Error::write(path, e))
    })
}

/// Write several files as one set ([`aeromag_io::atomic::write_files`]):
/// every target checked first, all written to temporaries, then renamed one
/// right after another, so an error or an interruption leaves either all
/// the old files or all the new ones. `em study` wrote its four files one
/// by one, seconds apart: SIGTERM left an earlier study's files mixed with
/// the new ones.
pub fn write_files(files: &[(&Path, &[u8])]) -> Result<()> {
    aeromag_io::atomic::write_files(files).map_err(|(path, e)| Error::write(path, e))
}

/// Write `path` by streaming into a buffered temporary file in the same
/// folder (`.NAME.PID.tmp`), renamed when `write` has succeeded and the
/// buffer is flushed; on any failure the temporary file is removed, so an
/// interrupted write never leaves a complete-looking partial file.
pub fn write_streamed(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<aeromag_io::atomic::Output>) -> Result<()>,
) -> Result<()> {
    // The library error of `write`, kept while the I/O layer sees a plain
    // I/O error.
    let mut failure: Option<Error> = None;
    let written = aeromag_io::atomic::write_atomically(path, |w| {
        write(w).map_err(|e| {
            failure = Some(e);
            std::io::Error::other("write failed")
        })
    });
    match (written, failure) {
        (_, Some(e)) => Err(e),
        (Err(e), None) => Err(Error::write(path, e)),
        (Ok(()), None) => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_and_reports_a_missing_folder() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("m.json");
        write_atomically(&p, b"one").unwrap();
        write_atomically(&p, b"two").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "two");
        assert_eq!(
            std::fs::read_dir(d.path()).unwrap().count(),
            1,
            "no temporary left"
        );
        let e = write_atomically(&d.path().join("no/such/m.json"), b"x").unwrap_err();
        assert!(!e.is_bad_input());
        assert!(e.to_string().contains("no/such/m.json"), "{e}");
    }

    /// `--model /dev/zero` grew to a gigabyte before running out of memory.
    #[cfg(unix)]
    #[test]
    fn an_endless_file_is_bad_input_after_the_limit() {
        let e = TlModel::read("/dev/zero").unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("larger than 64 MiB"),
            "{e}"
        );
        let e = kind_of("/dev/zero").unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains("larger than 64 MiB"),
            "{e}"
        );
    }

    #[test]
    fn a_file_that_is_not_a_model_is_bad_input() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("junk.json");
        std::fs::write(&p, "{\"format\":\"other\"}").unwrap();
        let e = TlModel::read(&p).unwrap_err();
        assert!(e.is_bad_input(), "{e}");
        assert!(e.to_string().contains("junk.json"), "{e}");
        let e = TlModel::read(d.path().join("none.json")).unwrap_err();
        assert!(e.is_bad_input());
    }
}
