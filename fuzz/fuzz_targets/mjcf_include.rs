//! The MJCF include resolver on a hostile file system (#60): the input
//! builds a model folder of files, folders, huge sparse files and
//! symlinks (out of the folder, to devices, to folders, to themselves),
//! then the main file's includes are inlined (`self_contained`, as a
//! scenario does) and the file is read as an arm (`from_mjcf_file`). Any
//! input gives text or a model, or a named error: never a panic, a hang,
//! an allocation past the caps, nor the text of the file outside the
//! folder in what is returned.
#![no_main]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

/// What the one MJCF file outside the model's folder holds: finding it in
/// a result is an include that escaped the folder.
const SECRET: &str = "FUZZ-SECRET-OUTSIDE-THE-MODEL";

/// Where an entry may be made: inside the model's folder only, so that
/// the fuzzer writes nowhere else.
const NAMES: [&str; 8] = [
    "a.xml",
    "b.xml",
    "sub/c.xml",
    "sub/d.xml",
    "sub",
    "sub/deeper",
    "e.xml",
    "link.xml",
];

/// Where a symlink may lead: out of the folder, to devices, to procfs (a
/// file whose size says 0), to folders, to itself, to nothing.
const TARGETS: [&str; 12] = [
    "../outside.xml",
    "..",
    "/dev/zero",
    "/dev/null",
    "/dev/urandom",
    "/etc/passwd",
    "/proc/self/status",
    "/tmp",
    "sub",
    "a.xml",
    "link.xml",
    "/nonexistent/fuzz",
];

/// Entries at most: enough for a DAG of includes, a cycle and a symlink.
const MAX_ENTRIES: usize = 16;

/// The scratch folder of this process: `outside.xml` and `model/`.
fn sandbox() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("fuzz-mjcf-include-{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let _ = std::fs::write(
            dir.join("outside.xml"),
            format!("<mujoco><!-- {SECRET} --><worldbody/></mujoco>"),
        );
        dir
    })
}

/// One entry of the model's folder, from a record of the input: its kind
/// (first byte), its name (second byte) and its contents (the rest). The
/// first pass makes files and folders, the second symlinks.
fn make(model: &Path, record: &[u8], links: bool) {
    let [kind, which, rest @ ..] = record else {
        return;
    };
    let path = model.join(NAMES[usize::from(*which) % NAMES.len()]);
    let Some(parent) = path.parent() else {
        return;
    };
    if links {
        // Never through a symlink made before (`sub` → /tmp): the link
        // would land outside the sandbox.
        let real_folder = std::fs::symlink_metadata(parent).is_ok_and(|m| m.is_dir());
        if kind % 4 == 3 && real_folder {
            let target = TARGETS[usize::from(rest.first().copied().unwrap_or(0)) % TARGETS.len()];
            let _ = std::os::unix::fs::symlink(target, &path);
        }
        return;
    }
    let _ = std::fs::create_dir_all(parent);
    match kind % 4 {
        0 => {
            let _ = std::fs::write(&path, rest);
        }
        1 => {
            let _ = std::fs::create_dir_all(&path);
        }
        // Sparse: 3 GB, or one byte past the 16 MiB cap.
        2 => {
            let len = match rest.first() {
                Some(b) if b % 2 == 0 => 3 << 30,
                _ => (16 << 20) + 1,
            };
            let _ = std::fs::File::create(&path).and_then(|f| f.set_len(len));
        }
        _ => {}
    }
}

fn assert_no_secret(what: &str, text: &str) {
    assert!(
        !text.contains(SECRET),
        "{what} holds the text of a file outside the model's folder"
    );
}

fuzz_target!(|data: &[u8]| {
    // The secret written by the input itself proves nothing.
    if data.windows(SECRET.len()).any(|w| w == SECRET.as_bytes()) {
        return;
    }
    let mut records = data.split(|&b| b == 0);
    let Some(main_text) = records.next() else {
        return;
    };
    let Ok(main_text) = std::str::from_utf8(main_text) else {
        return;
    };
    let model = sandbox().join("model");
    // remove_dir_all removes a symlink, never what it leads to.
    let _ = std::fs::remove_dir_all(&model);
    if std::fs::create_dir_all(&model).is_err() {
        return;
    }
    let records: Vec<&[u8]> = records.take(MAX_ENTRIES).collect();
    // Symlinks last, so that nothing is written through one.
    for links in [false, true] {
        for r in &records {
            make(&model, r, links);
        }
    }
    let main = model.join("main.xml");
    if std::fs::write(&main, main_text).is_err() {
        return;
    }
    match arm_model::ArmModel::self_contained(main_text, &model) {
        Ok(text) => assert_no_secret("the inlined text", &text),
        Err(e) => assert_no_secret("an error", &e.to_string()),
    }
    match arm_model::ArmModel::from_mjcf_file(&main, &Default::default()) {
        Ok(m) => assert_no_secret("the model", &format!("{m:?}")),
        Err(e) => assert_no_secret("an error", &e.to_string()),
    }
});
