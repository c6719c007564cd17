//! Prints the wire size of every message at its largest, against the DESIGN.md budgets.
//! Run: `cargo run -p figurine-protocol --example sizes`.

use figurine_protocol::*;

fn main() {
    let mut buf = [0u8; MAX_FRAME_LEN + 1];
    let pose = HostToDevice::Pose(Pose {
        seq: u16::MAX,
        t_us: u32::MAX,
        pos: [-1_000_000; 3],
        rot: [0xFF; 6],
    });
    let event = DeviceToHost::Event(ActionEvent {
        seq: u8::MAX,
        action: u8::MAX,
        end_seq: u16::MAX,
        len: u16::MAX,
        time: i8::MIN,
        weight: i8::MIN,
        distance: u8::MAX,
    });
    match (
        encode_frame_guarded(&pose, &mut buf),
        encode_frame(&event, &mut buf),
    ) {
        (Ok(p), Ok(e)) => {
            println!("Pose frame, worst case, with leading guard delimiter: {p} bytes (budget 32)");
            println!("ActionEvent frame, worst case: {e} bytes (budget 16)");
            println!("Largest frame of any message (buffer size): {MAX_FRAME_LEN} bytes");
        }
        (p, e) => eprintln!("encoding failed: {p:?} {e:?}"),
    }
}
