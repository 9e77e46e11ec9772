#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    rwt_fuzz_bevy::layer_checks::layer_file(data);
});
