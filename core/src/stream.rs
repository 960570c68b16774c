//! Copies into the frame's planes that bypass the cache. A frame's planes
//! (a 1080p frame: five of 8 MB) are written once per render, tile by tile,
//! and not read again while the lines would still be cached; a cached store
//! first reads each line it writes from memory. Non-temporal stores write
//! whole lines without that read: a 1080p frame's resolve, shading and store
//! took 0.6–1.7 ms less on two threads (`continuum compare`, 3dr-brute,
//! 3dr-full and raycast on the five benchmark scenes, alternated runs).

/// Four-byte plain values: any bits copied from one are one.
pub(crate) trait Word: Copy + sealed::Sealed {}

impl Word for u32 {}
impl Word for f32 {}

mod sealed {
    pub trait Sealed {}
    impl Sealed for u32 {}
    impl Sealed for f32 {}
}

/// `src` cut into rows of `dst[r].len()` values, one after the other, row
/// `r` copied into `dst[r]` — what `dst[r].copy_from_slice(..)` row by row
/// does, with non-temporal stores for each row's 16-byte-aligned middle on
/// x86-64 (SSE2, which every x86-64 CPU has). Fenced before it returns, so
/// every later read, on any thread, sees the copies. Panics if `src` holds
/// fewer values than the rows.
pub(crate) fn copy_rows<T: Word>(dst: &mut [&mut [T]], src: &[T]) {
    const { assert!(size_of::<T>() == 4) };
    let mut start = 0;
    for row in dst.iter_mut() {
        let from = &src[start..start + row.len()];
        start += row.len();
        copy_row(row, from);
    }
    // SAFETY: `_mm_sfence` needs SSE, which every x86-64 CPU has. It orders
    // the non-temporal stores above before every later store of this thread
    // (and so before whatever publishes the rows to another thread): the
    // fence their intrinsic asks for before the memory is accessed again.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        std::arch::x86_64::_mm_sfence();
    }
}

/// One row of [`copy_rows`], unfenced.
#[inline]
fn copy_row<T: Word>(row: &mut [T], from: &[T]) {
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
        for (out, four) in middle.iter_mut().zip(from_middle.chunks_exact(4)) {
            // SAFETY: `four` is four `Word`s, 16 readable bytes (unaligned
            // load); `out` is a live, aligned `__m128i` of the row. The
            // sfence `_mm_stream_si128` asks for before the memory is
            // accessed again is `copy_rows`'s, before it returns: nothing
            // here touches these bytes again.
            unsafe { _mm_stream_si128(out, _mm_loadu_si128(four.as_ptr().cast())) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    row.copy_from_slice(from);
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
