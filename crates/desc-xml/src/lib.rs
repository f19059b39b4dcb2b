//! What the generators of the description files share (`crates/esi` for the
//! EtherCAT ESI, `crates/gsdml` for the PROFINET GSDML): XML text escaping,
//! and the drift check their tests run on the committed files (also the one
//! the generated Markdown references of `drive-core` and `drive-pn` run,
//! [`check_file_current`]).
#![deny(missing_docs)]

use std::collections::BTreeSet;
use std::path::Path;

/// Appends `s` to `out` with `&`, `<`, `>`, `"` and `'` escaped (text and
/// attribute values).
pub fn escape_into(out: &mut String, s: &str) {
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
}

/// `s` escaped as by [`escape_into`].
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    escape_into(&mut out, s);
    out
}

/// The drift check of one generated file, `dir`/`name`: with the environment
/// variable `update` set, writes `text` there first; then the file must equal
/// `text`. `Err` says which file and how to regenerate (`command`).
pub fn check_file_current(
    dir: &Path,
    name: &str,
    text: &str,
    update: &str,
    command: &str,
) -> Result<(), String> {
    if std::env::var_os(update).is_some() {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
        std::fs::write(dir.join(name), text).map_err(|e| e.to_string())?;
    }
    let file = std::fs::read_to_string(dir.join(name)).unwrap_or_default();
    if file != text {
        let shown = dir.file_name().and_then(|n| n.to_str()).unwrap_or("?");
        return Err(format!("{shown}/{name} is out of date: run {update}=1 {command}"));
    }
    Ok(())
}

/// The drift check of a folder of generated files: [`check_file_current`] for
/// each of `files` (name, text) in `dir`, and `dir` must hold no other `.xml`
/// (a stale file from an earlier declaration). `Err` says which file and how
/// to regenerate (`command`).
pub fn check_current(
    dir: &Path,
    files: &[(String, String)],
    update: &str,
    command: &str,
) -> Result<(), String> {
    for (name, text) in files {
        check_file_current(dir, name, text, update, command)?;
    }
    let shown = dir.file_name().and_then(|n| n.to_str()).unwrap_or("?");
    let wanted: BTreeSet<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    for entry in std::fs::read_dir(dir).map_err(|e| e.to_string())? {
        let name = entry
            .map_err(|e| e.to_string())?
            .file_name()
            .into_string()
            .unwrap_or_default();
        if name.ends_with(".xml") && !wanted.contains(name.as_str()) {
            return Err(format!("{shown}/{name} is not generated: delete it"));
        }
    }
    Ok(())
}

/// A generator's `main`: writes `files` (name, text) into the directory
/// given as the first argument, else into `default_dir`, and prints each
/// path written.
pub fn write_all(default_dir: &Path, files: &[(String, String)]) -> std::io::Result<()> {
    let dir = std::env::args_os()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| default_dir.to_path_buf());
    std::fs::create_dir_all(&dir)?;
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_the_five_characters() {
        assert_eq!(escape(r#"a<b>&"c'"#), "a&lt;b&gt;&amp;&quot;c&apos;");
    }

    #[test]
    fn drift_check_finds_changed_and_stale_files() {
        let dir = std::env::temp_dir().join(format!("generated-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let files = vec![("a.xml".to_string(), "<a/>".to_string())];
        std::fs::write(dir.join("a.xml"), "<a/>").unwrap();
        assert_eq!(check_current(&dir, &files, "NO_SUCH_VAR_X", "cmd"), Ok(()));
        std::fs::write(dir.join("a.xml"), "<b/>").unwrap();
        assert!(check_current(&dir, &files, "NO_SUCH_VAR_X", "cmd")
            .unwrap_err()
            .contains("out of date"));
        std::fs::write(dir.join("a.xml"), "<a/>").unwrap();
        std::fs::write(dir.join("old.xml"), "").unwrap();
        assert!(check_current(&dir, &files, "NO_SUCH_VAR_X", "cmd")
            .unwrap_err()
            .contains("not generated"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn drift_check_of_one_file_names_it_and_its_command() {
        let dir = std::env::temp_dir().join(format!("generated-one-{}", std::process::id()));
        let check = |text: &str| check_file_current(&dir, "a.md", text, "NO_SUCH_VAR_Y", "cargo test x");
        assert!(check("text").is_err(), "no file yet");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("a.md"), "text").unwrap();
        assert_eq!(check("text"), Ok(()));
        let shown = dir.file_name().unwrap().to_str().unwrap().to_string();
        assert_eq!(
            check("new text"),
            Err(format!(
                "{shown}/a.md is out of date: run NO_SUCH_VAR_Y=1 cargo test x"
            ))
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
