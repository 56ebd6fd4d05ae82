//! EM raw record reader: `open_raw` (header, 3 channels, system check) and
//! the streaming body read in chunks as the detector does, then `read_raw`
//! on the same bytes in memory.
#![no_main]

use aeromag::em::files::open_raw;
use aeromag_em::sim::read_raw;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = aeromag_fuzz::scratch("in.raw", data);
    if let Ok(mut r) = open_raw(&path) {
        let mut out = Vec::new();
        // At most 64 chunks of 256 frames: the input is at most a few MB.
        for _ in 0..64 {
            match r.read_frames(256, &mut out) {
                Ok(0) | Err(_) => break,
                Ok(_) => {}
            }
        }
    }
    let _ = read_raw(data);
});
