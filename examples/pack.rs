//! Writes the showcase's asset pack (trees, a bush, a fern, a rock, flowers: glTF files
//! the examples make themselves) to `assets/generated/pack`, as `open_world` does when it
//! starts, for a build that cannot write files: the web page (`scripts/web.sh`) is served
//! the pack this writes.
//!
//! `cargo run --example pack`

fn main() {
    rwt_examples::pack::write_pack();
    println!("rwt-pack: {}", rwt_examples::pack::PACK.trees.len() + 4);
}
