//! Writes into the frame's planes that bypass the cache. A frame's planes
//! (a 1080p frame: five of 8 MB) are written once per render, tile by tile,
//! and not read again while the lines would still be cached; a cached store
//! first reads each line it writes from memory. Non-temporal stores write
//! whole lines without that read: the resolve's copies of depths and ids
//! took a 1080p frame's resolve, shading and store 0.6–1.7 ms lower on two
//! threads, and the shading's colours through them another 0.8–1.4 ms
//! together with cheaper counters and fills (`scripts/ab.py` on bunny,
//! soup, the dragon and Sponza; 2dr-brute, 3dr-brute, 3dr-full and
//! raycast; alternated runs).

/// Four-byte plain values: any bits copied from one are one.
pub(crate) trait Word: Copy + sealed::Sealed {}

impl Word for u32 {}
impl Word for f32 {}
impl Word for [u8; 4] {}

mod sealed {
    pub trait Sealed {}
    impl Sealed for u32 {}
    impl Sealed for f32 {}
    impl Sealed for [u8; 4] {}
}

/// `src` cut into rows of `dst[r].len()` values, one after the other, row
/// `r` copied into `dst[r]` — what `dst[r].copy_from_slice(..)` row by row
/// does, with non-temporal stores ([`Rows::write`]). Panics if `src` holds
/// fewer values than the rows.
pub(crate) fn copy_rows<T: Word>(dst: &mut [&mut [T]], src: &[T]) {
    streamed(dst, |rows| {
        let mut start = 0;
        for r in 0..rows.len() {
            let len = rows.row_len(r);
            rows.write(r, 0, &src[start..start + len]);
            start += len;
        }
    });
}

/// Runs `f` with `rows` behind a [`Rows`], through which it writes them
/// past the cache, and fences those writes before it returns (or unwinds),
/// so every later access, on any thread, sees them. While `f` runs the rows
/// are reachable only through the `Rows`.
pub(crate) fn streamed<T: Word, R>(rows: &mut [&mut [T]], f: impl FnOnce(&mut Rows<T>) -> R) -> R {
    /// Fences when dropped: after `f` returns and while it unwinds.
    struct Fence;
    impl Drop for Fence {
        fn drop(&mut self) {
            // SAFETY: `_mm_sfence` needs SSE, which every x86-64 CPU has.
            // It orders the non-temporal stores made through `Rows` before
            // every later access of this thread (and so before whatever
            // publishes the rows to another thread): the fence their
            // intrinsic asks for before the memory is accessed again.
            #[cfg(target_arch = "x86_64")]
            unsafe {
                std::arch::x86_64::_mm_sfence();
            }
        }
    }
    let _fence = Fence;
    f(&mut Rows { rows })
}

/// Rows written with non-temporal stores. Only [`streamed`] makes one, and
/// fences its writes when its closure ends, before the rows can be reached
/// another way.
pub(crate) struct Rows<'w, 'r, T> {
    rows: &'w mut [&'r mut [T]],
}

impl<T: Word> Rows<'_, '_, T> {
    /// How many rows.
    pub(crate) fn len(&self) -> usize {
        self.rows.len()
    }

    /// Row `r`'s length.
    pub(crate) fn row_len(&self, r: usize) -> usize {
        self.rows[r].len()
    }

    /// `row[start..start + from.len()].copy_from_slice(from)` of row `r`,
    /// with non-temporal stores for its 16-byte-aligned middle on x86-64
    /// (SSE2, which every x86-64 CPU has). Panics where the row is shorter.
    #[inline]
    pub(crate) fn write(&mut self, r: usize, start: usize, from: &[T]) {
        const { assert!(size_of::<T>() == 4) };
        let row = &mut self.rows[r][start..start + from.len()];
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{__m128i, _mm_loadu_si128, _mm_stream_si128};
            // SAFETY: every bit pattern is a valid `__m128i`, and a `Word`'s
            // bits are a valid `Word`: viewing the row's aligned middle as
            // `__m128i` (four `Word`s each, `Word`s being 4 bytes) reads or
            // writes nothing invalid.
            let (head, middle, tail) = unsafe { row.align_to_mut::<__m128i>() };
            let (from_head, rest) = from.split_at(head.len());
            let (from_middle, from_tail) = rest.split_at(middle.len() * 4);
            head.copy_from_slice(from_head);
            tail.copy_from_slice(from_tail);
            // A cache line (four stores) a step, then what is left.
            let (lines, rest) = middle.as_chunks_mut::<4>();
            let (from_lines, from_rest) = from_middle.as_chunks::<16>();
            let copy = |out: &mut __m128i, four: &[T]| {
                // SAFETY: `four` is four `Word`s, 16 readable bytes
                // (unaligned load); `out` is a live, aligned `__m128i` of the
                // row. The sfence `_mm_stream_si128` asks for before the
                // memory is accessed again is [`streamed`]'s, the only maker
                // of a `Rows`, when its closure ends; until then the row is
                // reachable only through this `Rows` (whose lifetimes the
                // closure cannot name, so it cannot trade it for another).
                unsafe { _mm_stream_si128(out, _mm_loadu_si128(four.as_ptr().cast())) };
            };
            for (line, from) in lines.iter_mut().zip(from_lines) {
                for (k, out) in line.iter_mut().enumerate() {
                    copy(out, &from[4 * k..][..4]);
                }
            }
            for (out, four) in rest.iter_mut().zip(from_rest.chunks_exact(4)) {
                copy(out, four);
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        row.copy_from_slice(from);
    }

    /// Every value of row `r` set to `value`, as [`Rows::write`] writes.
    #[inline]
    pub(crate) fn fill(&mut self, r: usize, value: T) {
        const { assert!(size_of::<T>() == 4) };
        let row = &mut *self.rows[r];
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{__m128i, _mm_loadu_si128, _mm_stream_si128};
            // SAFETY: as in `write`: no bits of a `__m128i` or a `Word` are invalid.
            let (head, middle, tail) = unsafe { row.align_to_mut::<__m128i>() };
            head.fill(value);
            tail.fill(value);
            let four = [value; 4];
            // SAFETY: `four` is 16 readable bytes (unaligned load).
            let four = unsafe { _mm_loadu_si128(four.as_ptr().cast()) };
            // A cache line (four stores) a step, then what is left.
            let (lines, rest) = middle.as_chunks_mut::<4>();
            let store = |out: &mut __m128i| {
                // SAFETY: `out` is a live, aligned `__m128i` of the row; the
                // fence is [`streamed`]'s, as in `write`.
                unsafe { _mm_stream_si128(out, four) };
            };
            for line in lines {
                line.iter_mut().for_each(store);
            }
            rest.iter_mut().for_each(store);
        }
        #[cfg(not(target_arch = "x86_64"))]
        row.fill(value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every row, whatever its length and its start's alignment (heads and
    /// tails of 0–3 values, rows shorter than one aligned block), holds
    /// exactly its part of the source afterwards, and nothing beside the
    /// rows is written.
    #[test]
    fn rows_are_copied_exactly() {
        let mut checked = 0;
        for offset in 0..4 {
            for len in [0, 1, 3, 4, 5, 7, 8, 15, 16, 17, 64, 257] {
                let rows = 3;
                let src: Vec<u32> = (0..(rows * len) as u32)
                    .map(|v| v.wrapping_mul(2654435761))
                    .collect();
                let mut plane = vec![u32::MAX; offset + rows * (len + 2)];
                let mut dst: Vec<&mut [u32]> = plane[offset..]
                    .chunks_mut(len + 2)
                    .map(|row| &mut row[1..len + 1])
                    .collect();
                copy_rows(&mut dst, &src);
                for (r, row) in plane[offset..].chunks(len + 2).enumerate() {
                    assert_eq!(row[0], u32::MAX, "before row {r}");
                    assert_eq!(&row[1..len + 1], &src[r * len..][..len], "row {r}");
                    assert_eq!(row[len + 1], u32::MAX, "after row {r}");
                }
                assert!(plane[..offset].iter().all(|&v| v == u32::MAX));
                checked += 1;
            }
        }
        assert_eq!(checked, 48);
    }

    /// A row filled, or written piece by piece at offsets, whatever its
    /// length and its start's alignment, holds exactly those values, and
    /// nothing beside it is written.
    #[test]
    fn rows_are_filled_and_written_in_pieces() {
        let mut checked = 0;
        for offset in 0..4 {
            for len in [0, 1, 3, 4, 5, 7, 8, 15, 16, 17, 64, 257] {
                let mut plane = vec![[9u8; 4]; offset + len + 2];
                let mut row = [&mut plane[offset + 1..offset + 1 + len]];
                streamed(&mut row, |rows| rows.fill(0, [1, 2, 3, 4]));
                assert!(
                    plane[offset + 1..][..len]
                        .iter()
                        .all(|&c| c == [1, 2, 3, 4])
                );
                assert!(plane[..=offset].iter().all(|&c| c == [9; 4]));
                assert_eq!(plane[offset + 1 + len], [9; 4]);
                let src: Vec<u32> = (0..len as u32)
                    .map(|v| v.wrapping_mul(2654435761))
                    .collect();
                let mut plane = vec![u32::MAX; offset + len + 2];
                let mut row = [&mut plane[offset + 1..offset + 1 + len]];
                streamed(&mut row, |rows| {
                    for start in (0..len).step_by(6) {
                        let end = (start + 6).min(len);
                        rows.write(0, start, &src[start..end]);
                    }
                });
                assert_eq!(&plane[offset + 1..][..len], &src[..]);
                assert!(plane[..=offset].iter().all(|&v| v == u32::MAX));
                assert_eq!(plane[offset + 1 + len], u32::MAX);
                checked += 1;
            }
        }
        assert_eq!(checked, 48);
    }

    #[test]
    fn floats_keep_their_bits() {
        let src = [
            f32::INFINITY,
            -0.0,
            f32::NAN,
            1.5,
            f32::MIN_POSITIVE,
            7.0,
            -2.0,
            0.1,
        ];
        let mut plane = [0.0f32; 8];
        copy_rows(&mut [&mut plane[..]], &src);
        assert_eq!(plane.map(f32::to_bits), src.map(f32::to_bits));
    }
}
