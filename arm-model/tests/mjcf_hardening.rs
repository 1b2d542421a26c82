//! MJCF reading hardened (#60 items 1, 2, 3 and 9): what an `<include>`
//! may read (inside the model's folder tree, regular MJCF files, within
//! size and count caps), and the values refused that used to pass (an
//! effort limit of zero, NaN or 1e308, a zero quaternion, an impossible
//! inertia, a home key outside its joint's range). Every file is made in
//! a scratch folder at test time.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use arm_model::{ArmModel, Locks, MAX_INCLUDED_FILES, MAX_URDF_BYTES, ModelError};

/// What the file outside the model's folder holds: no message may show it.
const SECRET: &str = "SECRET-60-OUTSIDE";

/// A scratch folder, removed when dropped: `model/` is the model's
/// folder, `outside/secret.xml` a valid MJCF file beside it.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let root = std::env::temp_dir().join(format!("arm-model-60-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("model/sub")).unwrap();
        std::fs::create_dir_all(root.join("outside")).unwrap();
        std::fs::write(
            root.join("outside/secret.xml"),
            format!("<mujoco><!-- {SECRET} --><worldbody/></mujoco>"),
        )
        .unwrap();
        Self(root)
    }

    fn model(&self) -> PathBuf {
        self.0.join("model")
    }

    /// Writes `text` at `name` in the model's folder; returns its path.
    fn write(&self, name: &str, text: &str) -> PathBuf {
        let path = self.model().join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    /// The main file including `file` (and an arm, so that it reads).
    fn including(&self, file: &str) -> PathBuf {
        self.write("main.xml", &arm(&format!(r#"<include file="{file}"/>"#)))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A one-joint arm with `extra` at the top level.
fn arm(extra: &str) -> String {
    format!(
        r#"<mujoco model="t"><compiler angle="radian"/>{extra}
  <worldbody><body name="b"><joint name="j" range="-1 1"/>
    <inertial mass="1" pos="0 0 0" diaginertia="0.1 0.1 0.1"/></body></worldbody>
</mujoco>"#
    )
}

fn load(path: &Path) -> Result<ArmModel, ModelError> {
    ArmModel::from_mjcf_file(path, &Locks::new())
}

/// The include refused as not included, its message checked for `want`
/// and for the outside file's text; the same through `self_contained`,
/// which a scenario uses.
fn refused(s: &Scratch, file: &str, want: &str) -> String {
    let main = s.including(file);
    let e = load(&main).unwrap_err();
    assert!(matches!(e, ModelError::MjcfInclude { .. }), "{file}: {e}");
    let text = std::fs::read_to_string(&main).unwrap();
    let alone = ArmModel::self_contained(&text, &s.model()).unwrap_err();
    assert_eq!(alone, e, "{file}: the same refusal as text");
    let e = e.to_string();
    assert!(e.contains(want), "{file}: {e}");
    assert!(
        e.starts_with("MJCF <include file="),
        "{file}: names the include: {e}"
    );
    assert!(!e.contains(SECRET), "{file}: shows the file's text: {e}");
    e
}

/// [`refused`] for the include written in the main file, named as written.
fn direct(s: &Scratch, file: &str, want: &str) -> String {
    let e = refused(s, file, want);
    assert!(
        e.starts_with(&format!(r#"MJCF <include file="{file}"/>"#)),
        "{file}: names the include: {e}"
    );
    e
}

// Item 1: an include reads only MJCF files inside the model's folder tree.

#[test]
fn an_include_outside_the_model_folder_is_refused_without_its_text() {
    let s = Scratch::new("outside");
    let secret = s.0.join("outside/secret.xml");
    let outside = "lies outside the model's folder";
    direct(&s, "../outside/secret.xml", outside);
    direct(&s, "sub/../../outside/secret.xml", outside);
    direct(&s, secret.to_str().unwrap(), outside);
    let e = direct(&s, "/etc/passwd", outside);
    assert!(!e.contains("root:"), "{e}");
    // A symlink inside the folder that leads out of it: both paths named.
    std::os::unix::fs::symlink(&secret, s.model().join("link.xml")).unwrap();
    let e = direct(&s, "link.xml", outside);
    assert!(
        e.contains(&format!("→ {}", secret.canonicalize().unwrap().display())),
        "{e}"
    );
    std::os::unix::fs::symlink("../outside", s.model().join("out")).unwrap();
    direct(&s, "out/secret.xml", outside);
}

#[test]
fn an_include_inside_the_folder_reads_by_any_path_that_stays_inside() {
    let s = Scratch::new("inside");
    s.write(
        "sub/part.xml",
        "<mujoco><option timestep='0.002'/></mujoco>",
    );
    std::os::unix::fs::symlink("sub/part.xml", s.model().join("alias.xml")).unwrap();
    let absolute = s.model().join("sub/part.xml");
    for file in [
        "sub/part.xml",
        "sub/../sub/part.xml",
        "alias.xml",
        absolute.to_str().unwrap(),
    ] {
        let m = load(&s.including(file));
        assert!(m.is_ok(), "{file}: {m:?}");
    }
}

#[test]
fn a_file_that_is_not_mjcf_is_refused_by_name_without_its_text() {
    let s = Scratch::new("not-mjcf");
    s.write("notes.txt", &format!("password={SECRET}\n"));
    s.write("robot.xml", &format!("<robot name='{SECRET}'/>"));
    s.write("bytes.xml", "<mujoco>\u{0}");
    for file in ["notes.txt", "robot.xml", "bytes.xml"] {
        direct(&s, file, "it is not an MJCF file");
    }
    std::fs::write(s.model().join("binary.xml"), b"\xff\xfe<mujoco/>").unwrap();
    direct(&s, "binary.xml", "it is not UTF-8 text");
}

/// Meshes, textures and height fields name files that are never read:
/// one that is a device, a folder, missing or outside the model's folder
/// changes nothing.
#[test]
fn mesh_texture_and_height_field_files_are_never_read() {
    let s = Scratch::new("meshes");
    let secret = s.0.join("outside/secret.xml");
    let assets = format!(
        r#"<asset><mesh name="m1" file="/dev/zero"/><mesh name="m2" file="{}"/>
        <mesh name="m3" file="sub"/><mesh name="m4" file="missing.stl"/>
        <texture name="t" type="2d" file="/dev/zero"/><hfield name="h" file="/dev/zero" size="1 1 1 1"/></asset>"#,
        secret.display()
    );
    let text = arm(&assets).replace(
        "<inertial",
        r#"<geom type="mesh" mesh="m1"/><geom type="mesh" mesh="m2"/><inertial"#,
    );
    let started = Instant::now();
    let m = load(&s.write("main.xml", &text)).unwrap();
    assert!(started.elapsed() < Duration::from_secs(5));
    assert_eq!(m.dof(), 1);
    assert!(!format!("{m:?}").contains(SECRET));
}

/// What the parser would read on its own, unchecked, is refused by name.
#[test]
fn a_prefixed_include_and_a_sub_model_are_refused_by_name() {
    let s = Scratch::new("parser-reads");
    let prefixed = arm(r#"<m:include xmlns:m="urn:x" file="/dev/zero"/>"#);
    let e = load(&s.write("main.xml", &prefixed))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("MJCF <m:include> (unnamed, line 1"), "{e}");
    assert!(e.contains("write it <include file=\"…\"/>"), "{e}");
    let sub = arm(r#"<asset><model name="hand" file="/dev/zero"/></asset>"#);
    let e = load(&s.write("main.xml", &sub)).unwrap_err().to_string();
    assert!(e.starts_with("MJCF <model name='hand'> (in "), "{e}");
    assert!(e.contains("a sub-model"), "{e}");
}

// Item 2: regular files only, sized before they are read.

#[test]
fn a_device_a_folder_and_a_fifo_are_refused_by_name_unread() {
    let s = Scratch::new("kinds");
    direct(
        &s,
        "/dev/zero",
        "it is a character device, not a regular file",
    );
    direct(&s, "sub", "it is a folder, not a regular file");
    std::os::unix::fs::symlink("/dev/zero", s.model().join("zero.xml")).unwrap();
    direct(&s, "zero.xml", "it is a character device");
    // Opening a FIFO blocks until a writer comes: refused before it is opened.
    let fifo = s.model().join("pipe.xml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|st| st.success()) {
        direct(&s, "pipe.xml", "it is a FIFO, not a regular file");
    }
}

#[test]
fn a_large_include_is_refused_from_its_size_before_it_is_read() {
    let s = Scratch::new("large");
    // 3 GB, sparse: reading it whole aborted the process.
    let big = std::fs::File::create(s.model().join("big.xml")).unwrap();
    big.set_len(3 << 30).unwrap();
    let started = Instant::now();
    let e = direct(
        &s,
        "big.xml",
        "over the cap of 16777216 bytes on a model file",
    );
    assert!(e.contains("it is 3221225472 bytes"), "{e}");
    assert!(started.elapsed() < Duration::from_secs(1));
    // One byte over the cap is over it.
    let over = std::fs::File::create(s.model().join("over.xml")).unwrap();
    over.set_len(MAX_URDF_BYTES as u64 + 1).unwrap();
    direct(&s, "over.xml", "it is 16777217 bytes");
}

#[test]
fn the_main_file_is_read_as_its_includes_are() {
    let s = Scratch::new("main-file");
    let e = load(Path::new("/dev/zero")).unwrap_err().to_string();
    assert!(e.contains("it is a character device"), "{e}");
    let big = s.model().join("big.xml");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(3 << 30)
        .unwrap();
    let e = load(&big).unwrap_err().to_string();
    assert!(e.contains("it is 3221225472 bytes or more"), "{e}");
    let urdf = s.write("arm.urdf", "<robot name='r'/>");
    let e = load(&urdf).unwrap_err().to_string();
    assert!(e.contains("not an MJCF file"), "{e}");
}

// Item 3: the whole expansion is capped, in files and in bytes.

/// `dag_k.xml` includes `dag_{k+1}.xml` four times, 15 levels: no cycle,
/// 4¹⁵ inclusions. It ran past 60 s at 781 MB.
#[test]
fn an_include_dag_is_refused_at_once_naming_the_cap() {
    let s = Scratch::new("dag");
    for k in 0..15 {
        let next = format!(r#"<include file="dag_{}.xml"/>"#, k + 1);
        s.write(
            &format!("dag_{k}.xml"),
            &format!("<mujoco>{}</mujoco>", next.repeat(4)),
        );
    }
    s.write("dag_15.xml", "<mujoco><option timestep='0.002'/></mujoco>");
    let started = Instant::now();
    let e = refused(
        &s,
        "dag_0.xml",
        &format!("more than {MAX_INCLUDED_FILES} inclusions"),
    );
    assert!(
        started.elapsed() < Duration::from_secs(1),
        "{:?}: {e}",
        started.elapsed()
    );
}

#[test]
fn includes_that_read_or_expand_past_the_byte_cap_are_refused() {
    let s = Scratch::new("bytes");
    let mb = format!("<mujoco><!-- {} --></mujoco>", "x".repeat(1 << 20));
    s.write("mb.xml", &mb);
    // Seventeen times a megabyte: more read than one model may read.
    let many = r#"<include file="mb.xml"/>"#.repeat(17);
    s.write("many.xml", &format!("<mujoco>{many}</mujoco>"));
    refused(
        &s,
        "many.xml",
        "the included files would add up to more than the cap of 16777216 bytes read",
    );
    // A 10 MB main file and a 7 MB include: read within the cap, the text
    // over it.
    s.write(
        "seven.xml",
        &format!("<mujoco><!-- {} --></mujoco>", "x".repeat(7 << 20)),
    );
    let pad = format!("<!-- {} -->", "y".repeat(10 << 20));
    let main = s.write(
        "main.xml",
        &arm(&format!(r#"{pad}<include file="seven.xml"/>"#)),
    );
    let e = load(&main).unwrap_err().to_string();
    assert!(
        e.contains("would pass the cap of 16777216 bytes on a model's text"),
        "{}",
        &e[..e.len().min(400)]
    );
}

#[test]
fn an_include_cycle_is_named_with_its_files() {
    let s = Scratch::new("cycle");
    s.write("a.xml", r#"<mujoco><include file="b.xml"/></mujoco>"#);
    s.write(
        "b.xml",
        r#"<mujoco><include file="sub/../a.xml"/></mujoco>"#,
    );
    refused(
        &s,
        "a.xml",
        "the file includes itself (a.xml → b.xml → a.xml)",
    );
}

// Item 9: values that used to pass.

/// The arm with an actuator and a joint written out.
fn driven(joint: &str, actuator: &str) -> String {
    format!(
        r#"<mujoco><compiler angle="radian"/><worldbody><body name="b"><joint name="j" range="-1 1" {joint}/>
    <inertial mass="1" pos="0 0 0" diaginertia="0.1 0.1 0.1"/></body></worldbody>
  <actuator>{actuator}</actuator></mujoco>"#
    )
}

fn refused_value(s: &Scratch, text: &str, want: &[&str]) -> String {
    let path = s.write("main.xml", text);
    let e = load(&path).unwrap_err();
    assert!(matches!(e, ModelError::MjcfRefused { .. }), "{e}");
    let e = e.to_string();
    for w in want {
        assert!(e.contains(w), "want {w:?}: {e}");
    }
    assert!(
        e.contains(&path.display().to_string()),
        "names the file: {e}"
    );
    e
}

#[test]
fn an_effort_limit_of_zero_or_not_a_number_is_refused_not_unlimited() {
    let s = Scratch::new("effort-zero");
    let motor = |attrs: &str| driven("", &format!(r#"<motor name="m" joint="j" {attrs}/>"#));
    let named = "<motor name='m'> on joint 'j'";
    refused_value(
        &s,
        &motor(r#"gear="nan" ctrlrange="-1 1""#),
        &[named, "gear NaN is not a finite, non-zero number"],
    );
    refused_value(
        &s,
        &motor(r#"gear="0" ctrlrange="-1 1""#),
        &[named, "gear 0 is not a finite, non-zero number"],
    );
    refused_value(
        &s,
        &motor(r#"ctrlrange="0 0""#),
        &[named, "ctrlrange \"0 0\" × gear 1 is an effort limit of 0"],
    );
    refused_value(
        &s,
        &driven(
            "",
            r#"<position name="p" joint="j" forcerange="0 0" forcelimited="true"/>"#,
        ),
        &["<position name='p'>", "forcerange \"0 0\""],
    );
    refused_value(
        &s,
        &driven(r#"actuatorfrcrange="0 0""#, ""),
        &["<joint name='j'>", "actuatorfrcrange", "effort limit of 0"],
    );
}

#[test]
fn an_absurd_effort_limit_is_refused() {
    let s = Scratch::new("effort-huge");
    let motor = |attrs: &str| driven("", &format!(r#"<motor name="m" joint="j" {attrs}/>"#));
    refused_value(
        &s,
        &motor(r#"gear="1e300" ctrlrange="-1 1""#),
        &["ctrlrange \"-1 1\" × gear 1e300 is an effort limit of 1e300, above 1e6"],
    );
    refused_value(
        &s,
        &motor(r#"ctrlrange="-1e308 1e308""#),
        &["ctrlrange \"-1e308 1e308\" × gear 1 is an effort limit of 1e308, above 1e6"],
    );
    refused_value(
        &s,
        &motor(r#"gear="1e200" ctrlrange="-1e200 1e200""#),
        &["is an effort limit of inf, not a finite number"],
    );
    // A real motor's limit still reads.
    let m = load(&s.write("main.xml", &motor(r#"gear="100" ctrlrange="-1 1""#))).unwrap();
    assert_eq!(m.joints[m.actuated[0]].effort, Some(100.0));
}

#[test]
fn a_zero_quaternion_is_refused_by_element() {
    let s = Scratch::new("quat");
    let text = arm("").replace(r#"<body name="b""#, r#"<body name="b" quat="0 0 0 0""#);
    refused_value(
        &s,
        &text,
        &[
            "MJCF <body name='b'>",
            "quat=\"0 0 0 0\" is a zero quaternion",
        ],
    );
}

#[test]
fn an_inertia_breaking_the_triangle_inequality_is_refused_unless_balanced() {
    let s = Scratch::new("triangle");
    let text = arm("").replace("0.1 0.1 0.1", "1 0.01 0.01");
    refused_value(
        &s,
        &text,
        &[
            "<inertial> in <body name='b'>",
            "break the triangle inequality (A + B ≥ C)",
        ],
    );
    // balanceinertia makes each moment their mean, as MuJoCo does; said.
    let balanced = text.replace("<compiler ", r#"<compiler balanceinertia="true" "#);
    let m = load(&s.write("main.xml", &balanced)).unwrap();
    let i = m.links.iter().find(|l| l.name == "b").unwrap().inertia;
    assert!(
        (i[0] - 0.34).abs() < 1e-12 && i[0] == i[3] && i[3] == i[5],
        "{i:?}"
    );
    assert!(
        m.notes.iter().any(|n| n.contains("balanceinertia")),
        "{:?}",
        m.notes
    );
}

#[test]
fn a_home_key_outside_the_range_or_not_finite_is_refused() {
    let s = Scratch::new("key");
    let keyed = |qpos: &str| {
        arm(&format!(
            r#"<keyframe><key name="home" qpos="{qpos}"/></keyframe>"#
        ))
    };
    refused_value(
        &s,
        &keyed("100"),
        &[
            "<key name='home'>",
            "qpos puts joint 'j' at 100 rad, outside its range [-1, 1] rad",
        ],
    );
    refused_value(
        &s,
        &keyed("inf"),
        &["<key name='home'>", "the value inf, not a finite number"],
    );
    refused_value(&s, &keyed("1e400"), &["the value inf"]);
    // A value at a limit, written rounded, is the limit.
    let m = load(&s.write("main.xml", &keyed("1.00001"))).unwrap();
    assert_eq!(m.home, Some(vec![1.00001]));
}

#[test]
fn a_home_key_is_checked_on_every_joint() {
    let s = Scratch::new("key-two");
    let text = r#"<mujoco><compiler angle="radian"/><worldbody>
  <body name="a"><joint name="ja" range="-1 1"/><inertial mass="1" pos="0 0 0" diaginertia="0.1 0.1 0.1"/>
    <body name="b"><joint name="jb" range="-1 1"/><inertial mass="1" pos="0 0 0" diaginertia="0.1 0.1 0.1"/></body></body>
  </worldbody><keyframe><key qpos="0.5 -100"/></keyframe></mujoco>"#;
    refused_value(&s, text, &["<key name='#0'>", "joint 'jb' at -100 rad"]);
}

/// Malformed MJCF is named as MJCF, from a file or as text.
#[test]
fn malformed_mjcf_is_named_as_mjcf_not_urdf() {
    let s = Scratch::new("malformed");
    let bomb = r#"<?xml version="1.0"?><!DOCTYPE mujoco [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]><mujoco model="&c;"><worldbody/></mujoco>"#;
    let xxe = r#"<?xml version="1.0"?><!DOCTYPE mujoco [<!ENTITY x SYSTEM "file:///etc/passwd">]><mujoco model="&x;"><worldbody/></mujoco>"#;
    let deep = format!(
        "<mujoco>{}{}</mujoco>",
        "<a>".repeat(150),
        "</a>".repeat(150)
    );
    for (what, text, want) in [
        ("entity bomb", bomb, "a <!DOCTYPE> is not read"),
        ("XXE", xxe, "a <!DOCTYPE> is not read"),
        (
            "nesting",
            deep.as_str(),
            "elements are nested more than 100 deep",
        ),
    ] {
        let e = ArmModel::from_urdf_str(text).unwrap_err().to_string();
        assert!(
            e.starts_with("not a valid MJCF: ") && e.contains(want),
            "{what}: {e}"
        );
        let e = load(&s.write("main.xml", text)).unwrap_err().to_string();
        assert!(
            e.starts_with("not a valid MJCF: ") && e.contains(want),
            "{what}: {e}"
        );
        assert!(!e.contains("root:"), "{what}: {e}");
    }
}
