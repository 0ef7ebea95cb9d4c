//! The candidate buffer every streaming decoder keeps (LDS-01, LDROBOT, RPLIDAR): the bytes of
//! a frame not yet complete or not yet judged, filled from the input in any chunking, and the
//! two ways a candidate leaves it: consumed as a frame, or rejected by resynchronising on the
//! next sync byte already buffered (so a good frame that begins inside a bad candidate is never
//! thrown away). `no_std`, fixed size `N`; the decoders count what is dropped.

/// Skips the front of `input` up to its first `sync` byte (all of it if there is none);
/// returns the bytes skipped. Hunting in the input itself copies no garbage.
pub(crate) fn skip_to(input: &mut &[u8], sync: u8) -> usize {
    let n = input.iter().position(|&b| b == sync).unwrap_or(input.len());
    *input = &input[n..];
    n
}

/// Up to `N` buffered bytes of a frame candidate.
#[derive(Debug, Clone)]
pub(crate) struct Candidate<const N: usize> {
    buf: [u8; N],
    len: usize,
}

impl<const N: usize> Default for Candidate<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Candidate<N> {
    /// An empty buffer.
    pub(crate) const fn new() -> Self {
        Candidate {
            buf: [0; N],
            len: 0,
        }
    }

    /// Bytes buffered.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// The buffered bytes.
    pub(crate) fn bytes(&self) -> &[u8] {
        &self.buf[..self.len]
    }

    /// Takes bytes from the front of `input` until `want` (at most `N`) are buffered; returns
    /// how many were taken. Nothing is taken when `want` or more are buffered already.
    pub(crate) fn fill(&mut self, input: &mut &[u8], want: usize) -> usize {
        let take = want.min(N).saturating_sub(self.len).min(input.len());
        self.buf[self.len..self.len + take].copy_from_slice(&input[..take]);
        self.len += take;
        *input = &input[take..];
        take
    }

    /// Removes `n` bytes (a frame) from the front, keeping what follows it.
    pub(crate) fn consume(&mut self, n: usize) {
        let n = n.min(self.len);
        self.buf.copy_within(n..self.len, 0);
        self.len -= n;
    }

    /// Empties the buffer; returns the bytes dropped.
    pub(crate) fn clear(&mut self) -> usize {
        core::mem::take(&mut self.len)
    }

    /// Rejects the candidate at the front: drops its first byte and everything up to the next
    /// `sync` byte already buffered (or all of it). Returns the bytes dropped.
    pub(crate) fn resync(&mut self, sync: u8) -> usize {
        let start = self.buf[1.min(self.len)..self.len]
            .iter()
            .position(|&b| b == sync)
            .map_or(self.len, |p| p + 1);
        self.consume(start);
        start
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn fill_consume_resync() {
        let mut c = Candidate::<8>::default();
        let mut input: &[u8] = &[0x54, 1, 2, 0x54, 3, 4, 5, 6, 7, 8];
        assert_eq!(c.fill(&mut input, 6), 6);
        assert_eq!(c.fill(&mut input, 6), 0);
        assert_eq!(c.bytes(), &[0x54, 1, 2, 0x54, 3, 4]);
        assert_eq!(c.resync(0x54), 3);
        assert_eq!(c.bytes(), &[0x54, 3, 4]);
        c.consume(2);
        assert_eq!(c.bytes(), &[4]);
        assert_eq!(c.resync(0x54), 1);
        assert_eq!(c.len(), 0);
        assert_eq!(c.resync(0x54), 0);
        assert_eq!(c.fill(&mut input, 100), 4);
        assert_eq!(c.clear(), 4);
        let mut input: &[u8] = &[1, 2, 0xFA, 3];
        assert_eq!(skip_to(&mut input, 0xFA), 2);
        assert_eq!(input, &[0xFA, 3]);
        assert_eq!(skip_to(&mut input, 0x54), 2);
        assert!(input.is_empty());
    }
}
