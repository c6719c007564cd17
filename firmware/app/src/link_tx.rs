//! Link transmit task: frames each outgoing message and writes it to the serial port.

use figurine_protocol::{encode_frame, MAX_FRAME_LEN};

use crate::board::SerialTx;
use crate::channels::OUTBOX;

/// Sends every message of the outbox, in order, forever.
#[embassy_executor::task]
pub async fn task(mut tx: SerialTx) {
    let mut frame = [0u8; MAX_FRAME_LEN];
    loop {
        let msg = OUTBOX.receive().await;
        match encode_frame(&msg, &mut frame) {
            Ok(n) => tx.write_all(frame.get(..n).unwrap_or(&[])).await,
            // Every DeviceToHost fits MAX_FRAME_LEN (checked by the protocol's size tests).
            Err(e) => defmt::error!("cannot frame {}: {}", msg, e),
        }
    }
}
