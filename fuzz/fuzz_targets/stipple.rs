#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    rwt_fuzz::core_checks::stipple(data);
});
