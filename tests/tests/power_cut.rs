//! A power cut in the middle of a library upload (flash fault injection on the emulated
//! board: the core resets with a half-programmed word) leaves the previous library active
//! and intact after the reboot; the next upload then succeeds.

use figurine_e2e::{Qemu, QemuOptions};
use figurine_host::link::blobs::{self, Blobs};
use figurine_host::link::cli::upload_to;
use figurine_host::link::{replay_log, LinkError, ReplayOptions};
use std::sync::OnceLock;

use figurine_host::recognize::eval::learn_synth_library;
use figurine_host::recognize::simulate::simulate_log;
use figurine_host::synth::knobs::Knobs;
use figurine_host::synth::sequence::sequence;
use figurine_protocol::BlobKind;
use figurine_recognizer::EffortModel;

/// Bytes of the slot header the store writes after the blob.
const HEADER_LEN: u32 = 32;

/// The library in use before the cut (learnt from synthetic examples, as a user's
/// `figurine learn` would) with the default effort model, and a different library blob (the
/// same actions in reverse order) to upload when the power fails. Learnt once per run.
fn libraries() -> &'static (Blobs, Vec<u8>) {
    static LIBS: OnceLock<(Blobs, Vec<u8>)> = OnceLock::new();
    LIBS.get_or_init(|| {
        let mut lib = learn_synth_library(5, 3, &Knobs::default()).expect("learn");
        let old = Blobs {
            names: lib.names(),
            library: lib.blob().expect("library blob"),
            effort: blobs::load(None, None).expect("default effort").effort,
        };
        lib.actions.reverse();
        let new = lib.blob().expect("reversed library blob");
        assert_ne!(new, old.library);
        (old, new)
    })
}

/// Cuts the power during the third upload since boot (library, effort, then the new
/// library) after `after_bytes` bytes; returns nothing, asserts everything.
fn cut_case(after_bytes: u32, check_events: bool) {
    let (old, new) = libraries();
    let mut q = Qemu::start(&QemuOptions {
        cut: Some((3, after_bytes)),
        ..QemuOptions::default()
    })
    .expect("start QEMU");
    let mut dev = q.connect().expect("connect");
    upload_to(&mut dev, old, true).expect("first upload");
    let old_crc = blobs::crc32(&old.library);
    assert_eq!(dev.hello().library_crc, old_crc);

    match dev.upload(BlobKind::Library, new, |_, _| {}) {
        Err(LinkError::Rebooted(_)) => {}
        other => panic!("cut after {after_bytes} B: expected a reboot, got {other:?}"),
    }
    let hello = dev.handshake().expect("handshake after the reboot");
    assert_eq!(
        hello.library_crc, old_crc,
        "cut after {after_bytes} B: previous library lost"
    );
    assert_eq!(hello.effort_crc, blobs::crc32(&old.effort));

    if check_events {
        // Intact: it recognises exactly what simulation with the old library does.
        let log = sequence(11, &Knobs::default(), 4, None).log;
        let effort = EffortModel::from_bytes(&old.effort).expect("effort");
        let sim = simulate_log(&log, &old.names, &old.library, Some(effort)).expect("simulate");
        let got = replay_log(
            &mut dev,
            &log,
            &old.names,
            ReplayOptions::default(),
            |_, _| {},
        )
        .expect("replay");
        assert_eq!(got.records, sim.records);
    }

    // The cut fires once; the retried upload goes through and survives a reconnect.
    let crc = dev
        .upload(BlobKind::Library, new, |_, _| {})
        .expect("retry");
    assert_eq!(crc, blobs::crc32(new));
    drop(dev);
    assert_eq!(q.connect().expect("reconnect").hello().library_crc, crc);
    assert!(q.exited().unwrap().is_none());
}

#[test]
fn power_cut_right_after_the_erase_keeps_the_previous_library() {
    cut_case(0, false);
}

#[test]
fn power_cut_in_the_middle_of_the_blob_keeps_the_previous_library_intact() {
    let (_, new) = libraries();
    cut_case(new.len() as u32 / 2, true);
}

#[test]
fn power_cut_while_writing_the_commit_header_keeps_the_previous_library() {
    let (_, new) = libraries();
    let padded = (new.len() as u32).div_ceil(4) * 4;
    cut_case(padded + HEADER_LEN / 4, false);
}
