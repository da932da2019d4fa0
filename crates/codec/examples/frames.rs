//! Taking length-prefixed frames off a byte stream that arrives in pieces, with
//! [`tendril_codec::Decoded`]: `cargo run -p tendril-codec --example frames`.

use tendril_codec::Decoded;

/// One length byte, then that many bytes; a zero length is not a frame.
fn decode(buf: &[u8]) -> Decoded<Vec<u8>, &'static str> {
    match buf.first() {
        None => Decoded::NeedMore,
        Some(0) => Decoded::Invalid { error: "empty frame", consumed: 1 },
        Some(&n) if buf.len() > usize::from(n) => {
            Decoded::Frame { packet: buf[1..=usize::from(n)].to_vec(), consumed: usize::from(n) + 1 }
        }
        Some(_) => Decoded::NeedMore,
    }
}

fn main() {
    let pieces: [&[u8]; 3] = [&[3, b'a'], &[b'b', b'c', 0, 2], b"ok"];
    let mut buf = Vec::new();
    for piece in pieces {
        buf.extend_from_slice(piece);
        loop {
            match decode(&buf) {
                Decoded::NeedMore => break,
                Decoded::Frame { packet, consumed } => {
                    println!("frame {:?}", String::from_utf8_lossy(&packet));
                    buf.drain(..consumed);
                }
                Decoded::Invalid { error, consumed } => {
                    println!("skipped {consumed} byte(s): {error}");
                    buf.drain(..consumed);
                }
            }
        }
    }
}
