//! A live pose stream as text lines (`figurine track … | figurine live`, or any tracker that
//! prints the pose-log format): each line is a sample, a header or comment, or garbage that is
//! counted and dropped. Bad input never ends the stream — a tracker that prints a stray binary
//! byte or a half-written line mid-session must not end the child's play — and nothing valid
//! after it is lost. Only a real read error (the pipe itself failing) ends it.
//!
//! | line | outcome |
//! |---|---|
//! | `t,x,y,z,qw,qx,qy,qz[,…]`, numbers | a sample |
//! | blank, `#…`, or the header `t,x,…` | skipped, not counted |
//! | anything else (too few fields, not numbers, not UTF-8) | dropped and counted in [`LineCounts::malformed`] |
//! | longer than [`MAX_LINE_BYTES`] | dropped and counted in [`LineCounts::too_long`]; the stream resumes at the next newline |

use std::io::BufRead;

use crate::poselog::PoseSample;

/// Longest line kept, bytes: a pose line is under 200; a longer one is garbage (a binary
/// stream on the pipe), dropped without holding more than this in memory.
pub const MAX_LINE_BYTES: usize = 4096;

/// What a pose stream held besides its samples.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct LineCounts {
    /// Samples read.
    pub samples: u64,
    /// Lines that were neither a sample nor a header, comment or blank.
    pub malformed: u64,
    /// Lines longer than [`MAX_LINE_BYTES`].
    pub too_long: u64,
}

impl LineCounts {
    /// Lines dropped, of any kind.
    pub fn dropped(&self) -> u64 {
        self.malformed + self.too_long
    }
}

/// Parses one pose CSV data line (`t,x,y,z,qw,qx,qy,qz[,…]`); `None` for a header, a
/// comment, a blank or malformed line.
pub fn parse_pose_line(line: &str) -> Option<PoseSample> {
    let line = line.trim();
    if line.is_empty() || line.starts_with('#') {
        return None;
    }
    let mut v = [0f64; 8];
    let mut fields = line.split(',');
    for slot in &mut v {
        *slot = fields.next()?.trim().parse().ok()?;
    }
    Some(PoseSample {
        t: v[0],
        pos: [v[1], v[2], v[3]],
        quat: [v[4], v[5], v[6], v[7]],
    })
}

/// Whether a line that is no sample is one a pose log may hold (blank, comment, header).
fn is_expected(line: &str) -> bool {
    let line = line.trim();
    line.is_empty()
        || line.starts_with('#')
        || line
            .split(',')
            .next()
            .is_some_and(|f| f.trim().eq_ignore_ascii_case("t"))
}

/// The samples of a pose stream, in order (see the module doc for what is dropped).
pub struct PoseLines<R> {
    reader: R,
    buf: Vec<u8>,
    counts: LineCounts,
}

impl<R: BufRead> PoseLines<R> {
    /// A stream over `reader`.
    pub fn new(reader: R) -> Self {
        Self {
            reader,
            buf: Vec::new(),
            counts: LineCounts::default(),
        }
    }

    /// What was read so far.
    pub fn counts(&self) -> LineCounts {
        self.counts
    }

    /// The next sample; `Ok(None)` at the end of the stream, `Err` only when reading fails.
    pub fn next_sample(&mut self) -> std::io::Result<Option<PoseSample>> {
        loop {
            let Some(too_long) = self.read_line()? else {
                return Ok(None);
            };
            if too_long {
                self.counts.too_long += 1;
                continue;
            }
            let Ok(text) = std::str::from_utf8(&self.buf) else {
                self.counts.malformed += 1;
                continue;
            };
            match parse_pose_line(text) {
                Some(p) => {
                    self.counts.samples += 1;
                    return Ok(Some(p));
                }
                None if is_expected(text) => {}
                None => self.counts.malformed += 1,
            }
        }
    }

    /// Reads the next line into `buf` (without its newline): `Some(true)` when it was longer
    /// than [`MAX_LINE_BYTES`] (then `buf` holds only its start), `None` at the end.
    fn read_line(&mut self) -> std::io::Result<Option<bool>> {
        self.buf.clear();
        let mut too_long = false;
        let mut any = false;
        loop {
            let chunk = match self.reader.fill_buf() {
                Ok(c) => c,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if chunk.is_empty() {
                return Ok(any.then_some(too_long));
            }
            any = true;
            let (line, used, done) = match chunk.iter().position(|&b| b == b'\n') {
                Some(i) => (&chunk[..i], i + 1, true),
                None => (chunk, chunk.len(), false),
            };
            let room = MAX_LINE_BYTES.saturating_sub(self.buf.len());
            if line.len() > room {
                too_long = true;
            }
            self.buf.extend_from_slice(&line[..line.len().min(room)]);
            self.reader.consume(used);
            if done {
                return Ok(Some(too_long));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(bytes: &[u8]) -> (Vec<PoseSample>, LineCounts) {
        let mut lines = PoseLines::new(bytes);
        let mut out = Vec::new();
        while let Some(p) = lines.next_sample().unwrap() {
            out.push(p);
        }
        (out, lines.counts())
    }

    #[test]
    fn pose_lines_parse_and_bad_lines_are_skipped() {
        let p = parse_pose_line("0.5,1,2,3,1,0,0,0,extra").unwrap();
        assert_eq!(p.t, 0.5);
        assert_eq!(p.pos, [1.0, 2.0, 3.0]);
        assert!(parse_pose_line("t,x,y,z,qw,qx,qy,qz").is_none());
        assert!(parse_pose_line("# comment").is_none());
        assert!(parse_pose_line("1,2,3").is_none());
        assert!(parse_pose_line("").is_none());
    }

    /// A stray binary byte, a half-written line and a runaway line in the middle of a stream
    /// are each one counted drop; every sample around them arrives, in order.
    #[test]
    fn garbage_in_the_stream_is_counted_and_the_samples_after_it_arrive() {
        let mut s = b"t,x,y,z,qw,qx,qy,qz\n# tracker v1\n0.00,0,0,0,1,0,0,0\n".to_vec();
        s.extend(b"0.01,0,0,\xff\xfe,1,0,0,0\n");
        s.extend(b"0.02,0.1,0,0,1,0,0,0\r\n\n");
        s.extend(b"0.03,0.2,0,0\n");
        s.extend(vec![b'7'; 3 * MAX_LINE_BYTES]);
        s.extend(b"\n0.04,0.3,0,0,1,0,0,0\n0.05,0.4,0,0,1,0,0,0");
        let (samples, counts) = read_all(&s);
        let t: Vec<f64> = samples.iter().map(|p| p.t).collect();
        assert_eq!(t, [0.0, 0.02, 0.04, 0.05]);
        assert_eq!(samples[3].pos[0], 0.4);
        assert_eq!(
            counts,
            LineCounts {
                samples: 4,
                malformed: 2,
                too_long: 1
            }
        );
        assert_eq!(counts.dropped(), 3);
    }

    /// A reader that hands out one byte at a time still gives whole lines.
    #[test]
    fn lines_split_across_reads_are_whole() {
        let text = b"0.00,1,2,3,1,0,0,0\n0.01,4,5,6,1,0,0,0\n";
        let reader = std::io::BufReader::with_capacity(1, &text[..]);
        let mut lines = PoseLines::new(reader);
        let a = lines.next_sample().unwrap().unwrap();
        let b = lines.next_sample().unwrap().unwrap();
        assert_eq!((a.pos, b.pos), ([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]));
        assert!(lines.next_sample().unwrap().is_none());
    }
}
