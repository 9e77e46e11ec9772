//! One buffer holding every chunk's instances ([`InstanceSlab`]), so that culling reads all
//! of them through one binding and tests every chunk of a view in one dispatch.
//!
//! Each chunk reads a range of instances, placed best-fit among the free ranges
//! ([`Ranges`]); chunks drawing the same instances (an asset's primitives at each level, a
//! class's meshes and its impostors) read one range, uploaded once ([`Shares`]). The buffer grows by doubling (copied on the GPU) up to what one storage
//! binding may hold; a chunk that does not fit then gets a buffer of its own and is drawn
//! whole. When the chunks hold a quarter of it or less (the camera left a dense area), it
//! shrinks by halving, the chunks' ranges packed from the start.

use crate::instancing::chunk::{GPU_BYTES_PER_INSTANCE, InstanceBuffer};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use std::collections::BTreeMap;
use std::ops::Range;
use std::sync::Arc;

/// Bytes of one instance.
const INSTANCE_BYTES: u64 = GPU_BYTES_PER_INSTANCE as u64;
/// The smallest buffer made (instances).
const FIRST_CAPACITY: u32 = 1 << 16;

/// Free ranges of a run of `capacity` slots, handed out best-fit and merged when freed.
#[derive(Debug, Default)]
pub(super) struct Ranges {
    capacity: u32,
    /// Free ranges, start to length, never adjacent.
    free: BTreeMap<u32, u32>,
}

impl Ranges {
    /// A range of `len` slots (`len` > 0), the smallest free one that holds it (the lowest
    /// of equals); `None` when none does.
    pub fn take(&mut self, len: u32) -> Option<Range<u32>> {
        let (&start, &free) = self
            .free
            .iter()
            .filter(|&(_, &free)| free >= len)
            .min_by_key(|&(&start, &free)| (free, start))?;
        self.free.remove(&start);
        if free > len {
            self.free.insert(start + len, free - len);
        }
        Some(start..start + len)
    }

    /// Gives `range` back, merged with the free ranges beside it.
    pub fn give(&mut self, range: Range<u32>) {
        let (mut start, mut len) = (range.start, range.len() as u32);
        if let Some((&before, &before_len)) = self.free.range(..start).next_back()
            && before + before_len == start
        {
            self.free.remove(&before);
            start = before;
            len += before_len;
        }
        if let Some(after_len) = self.free.remove(&(start + len)) {
            len += after_len;
        }
        self.free.insert(start, len);
    }

    /// Grows the run to `capacity` slots, the new ones free.
    pub fn grow(&mut self, capacity: u32) {
        if capacity > self.capacity {
            let old = std::mem::replace(&mut self.capacity, capacity);
            self.give(old..capacity);
        }
    }

    /// The largest free range's length.
    fn largest(&self) -> u32 {
        self.free.values().copied().max().unwrap_or(0)
    }

    /// Slots in use.
    fn used(&self) -> u32 {
        self.capacity - self.free.values().sum::<u32>()
    }

    /// The capacity to shrink to, halving while `used` slots are a quarter of it or less
    /// and it stays at least `floor`; `None` when it would not shrink.
    fn shrunk(&self, floor: u32) -> Option<u32> {
        let used = u64::from(self.used());
        let mut capacity = self.capacity;
        while capacity / 2 >= floor && used * 4 <= u64::from(capacity) {
            capacity /= 2;
        }
        (capacity < self.capacity).then_some(capacity)
    }
}

/// Where each of `ranges` goes when they are packed from slot 0 in order of their start:
/// `(owner, from, to start)`.
fn packed<K: Copy>(ranges: impl IntoIterator<Item = (K, Range<u32>)>) -> Vec<(K, Range<u32>, u32)> {
    let mut ranges: Vec<(K, Range<u32>)> = ranges.into_iter().collect();
    ranges.sort_by_key(|(_, r)| r.start);
    let mut next = 0;
    ranges
        .into_iter()
        .map(|(owner, from)| {
            let to = next;
            next += from.len() as u32;
            (owner, from, to)
        })
        .collect()
}

/// A buffer's identity while a share holds it (its address).
type BufferKey = usize;

/// One range of instances and the chunks reading it.
#[derive(Debug)]
struct Share {
    range: Range<u32>,
    readers: u32,
    /// Held, so that no other buffer takes its address while the share stands.
    _buffer: Arc<InstanceBuffer>,
}

/// Which chunks read which range: one per chunk buffer, however many chunks draw it.
#[derive(Debug, Default)]
struct Shares {
    chunks: HashMap<Entity, BufferKey>,
    buffers: HashMap<BufferKey, Share>,
}

impl Shares {
    fn key(buffer: &Arc<InstanceBuffer>) -> BufferKey {
        Arc::as_ptr(buffer) as BufferKey
    }

    fn range(&self, chunk: Entity) -> Option<Range<u32>> {
        let key = self.chunks.get(&chunk)?;
        self.buffers.get(key).map(|s| s.range.clone())
    }

    /// `chunk` reads `buffer`'s range, if it has one already.
    fn join(&mut self, chunk: Entity, buffer: &Arc<InstanceBuffer>) -> bool {
        let key = Self::key(buffer);
        let Some(share) = self.buffers.get_mut(&key) else {
            return false;
        };
        share.readers += 1;
        self.chunks.insert(chunk, key);
        true
    }

    /// `chunk` reads `buffer`, newly placed at `range`.
    fn insert(&mut self, chunk: Entity, buffer: &Arc<InstanceBuffer>, range: Range<u32>) {
        let key = Self::key(buffer);
        let share = Share {
            range,
            readers: 1,
            _buffer: buffer.clone(),
        };
        self.buffers.insert(key, share);
        self.chunks.insert(chunk, key);
    }

    /// `chunk` reads nothing; returns the range no chunk reads any more, if that freed one.
    fn leave(&mut self, chunk: Entity) -> Option<Range<u32>> {
        let key = self.chunks.remove(&chunk)?;
        let share = self.buffers.get_mut(&key)?;
        share.readers -= 1;
        if share.readers > 0 {
            return None;
        }
        self.buffers.remove(&key).map(|s| s.range)
    }
}

/// Every chunk's instances in one buffer, by chunk render entity.
#[derive(Resource, Default)]
pub(in crate::instancing) struct InstanceSlab {
    buffer: Option<Buffer>,
    ranges: Ranges,
    shares: Shares,
}

impl InstanceSlab {
    /// The buffer, once a chunk was placed.
    pub fn buffer(&self) -> Option<&Buffer> {
        self.buffer.as_ref()
    }

    /// Instances the buffer holds (0 before the first chunk).
    #[cfg(feature = "testing")]
    pub fn capacity(&self) -> u32 {
        self.buffer.as_ref().map_or(0, |_| self.ranges.capacity)
    }

    /// The instances `chunk` reads.
    pub fn range(&self, chunk: Entity) -> Option<Range<u32>> {
        self.shares.range(chunk)
    }

    /// The bytes of `chunk`'s instances, and the buffer.
    pub fn slice(&self, chunk: Entity) -> Option<(&Buffer, Range<u64>)> {
        let range = self.shares.range(chunk)?;
        let bytes = u64::from(range.start) * INSTANCE_BYTES..u64::from(range.end) * INSTANCE_BYTES;
        Some((self.buffer.as_ref()?, bytes))
    }

    /// Places `buffer`'s instances (at least one) as `chunk`'s, in place of any it read:
    /// the range another chunk of the same buffer reads, else a new one; `false` when the
    /// slab cannot grow to hold them (nothing read then).
    pub fn place(
        &mut self,
        chunk: Entity,
        buffer: &Arc<InstanceBuffer>,
        device: &RenderDevice,
        queue: &RenderQueue,
    ) -> bool {
        self.free(chunk);
        if self.shares.join(chunk, buffer) {
            return true;
        }
        let instances = &buffer.instances;
        let Ok(len) = u32::try_from(instances.len()) else {
            return false;
        };
        if len == 0 {
            return false;
        }
        if self.ranges.largest() < len && !self.grow(len, device, queue) {
            return false;
        }
        let Some(range) = self.ranges.take(len) else {
            return false;
        };
        if let Some(slab) = &self.buffer {
            let at = u64::from(range.start) * INSTANCE_BYTES;
            queue.write_buffer(slab, at, bytemuck::cast_slice(instances));
        }
        self.shares.insert(chunk, buffer, range);
        true
    }

    /// Frees the ranges of the chunks `live` no longer holds.
    pub fn keep_only(&mut self, live: impl Fn(Entity) -> bool) {
        let chunks = self.shares.chunks.keys();
        let gone: Vec<Entity> = chunks.copied().filter(|&e| !live(e)).collect();
        for chunk in gone {
            self.free(chunk);
        }
    }

    /// Makes the buffer anew at a half, a quarter... of its size when the chunks use a
    /// quarter of it or less, their instances copied to ranges packed from the start. Call
    /// it after the frame's placements, so that it does not shrink what they then regrow.
    pub fn shrink_to_fit(&mut self, device: &RenderDevice, queue: &RenderQueue) {
        let (Some(old_buffer), Some(capacity)) = (&self.buffer, self.ranges.shrunk(FIRST_CAPACITY))
        else {
            return;
        };
        let buffer = slab_buffer(device, capacity);
        let shares = self.shares.buffers.iter();
        let moves = packed(shares.map(|(&key, share)| (key, share.range.clone())));
        let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor {
            label: Some("rwt_instance_slab_shrink"),
        });
        let mut ranges = Ranges::default();
        ranges.grow(capacity);
        for (key, from, to) in moves {
            let len = from.len() as u32;
            encoder.copy_buffer_to_buffer(
                old_buffer,
                u64::from(from.start) * INSTANCE_BYTES,
                &buffer,
                u64::from(to) * INSTANCE_BYTES,
                u64::from(len) * INSTANCE_BYTES,
            );
            let taken = ranges.take(len);
            debug_assert_eq!(taken, Some(to..to + len), "packing takes ranges in order");
            if let Some(share) = self.shares.buffers.get_mut(&key) {
                share.range = to..to + len;
            }
        }
        // Submitted now, as when growing: writes queued before land in the old buffer first.
        queue.submit([encoder.finish()]);
        self.buffer = Some(buffer);
        self.ranges = ranges;
    }

    fn free(&mut self, chunk: Entity) {
        if let Some(range) = self.shares.leave(chunk) {
            self.ranges.give(range);
        }
    }

    /// Makes the buffer anew with room for `len` more instances in one range (doubling),
    /// the old one's instances copied over; `false` past one binding's limit.
    fn grow(&mut self, len: u32, device: &RenderDevice, queue: &RenderQueue) -> bool {
        let limit = most_instances(device);
        if limit == 0 {
            // No storage buffers (WebGL2): nothing culls, every chunk draws its own buffer.
            return false;
        }
        let old = self.ranges.capacity;
        // The free range at the end, if any, grows with the buffer.
        let tail = self
            .ranges
            .free
            .last_key_value()
            .filter(|&(&start, &free)| start + free == old)
            .map_or(0, |(_, &free)| free);
        let need = u64::from(old) + u64::from(len - tail);
        let capacity = need
            .max(2 * u64::from(old))
            .max(u64::from(FIRST_CAPACITY))
            .min(limit);
        if capacity < need {
            warn_once!("rwt: instances pass what one GPU binding holds; drawing some chunks whole");
            return false;
        }
        let capacity = capacity as u32;
        let buffer = slab_buffer(device, capacity);
        if let Some(old_buffer) = &self.buffer {
            // Submitted now: writes queued before it land in the old buffer first, those
            // queued after in the new one.
            let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor {
                label: Some("rwt_instance_slab_grow"),
            });
            encoder.copy_buffer_to_buffer(old_buffer, 0, &buffer, 0, old_buffer.size());
            queue.submit([encoder.finish()]);
        }
        self.buffer = Some(buffer);
        self.ranges.grow(capacity);
        true
    }
}

/// A slab buffer of `capacity` instances.
fn slab_buffer(device: &RenderDevice, capacity: u32) -> Buffer {
    device.create_buffer(&BufferDescriptor {
        label: Some("rwt_instance_slab"),
        size: u64::from(capacity) * INSTANCE_BYTES,
        usage: BufferUsages::VERTEX
            | BufferUsages::STORAGE
            | BufferUsages::COPY_DST
            | BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// The most instances one buffer may hold: what one storage binding and one buffer may.
fn most_instances(device: &RenderDevice) -> u64 {
    let limits = device.limits();
    let bytes = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    (bytes / INSTANCE_BYTES).min(u64::from(u32::MAX))
}

#[cfg(test)]
mod tests {
    use super::{Arc, Entity, InstanceBuffer, Ranges, Shares, packed};
    use crate::instancing::chunk::GpuInstance;

    #[test]
    fn chunks_of_one_buffer_share_its_range_until_the_last_leaves() {
        let buffer = |n: usize| {
            Arc::new(InstanceBuffer {
                instances: vec![GpuInstance::default(); n],
                ..Default::default()
            })
        };
        let (tree, rock) = (buffer(3), buffer(2));
        let [bark, leaves, card, stone] =
            [1, 2, 3, 4].map(Entity::from_raw_u32).map(Option::unwrap);
        let mut shares = Shares::default();
        assert!(!shares.join(bark, &tree), "nothing placed yet");
        shares.insert(bark, &tree, 0..3);
        assert!(shares.join(leaves, &tree) && shares.join(card, &tree));
        assert!(!shares.join(stone, &rock), "another buffer, another range");
        shares.insert(stone, &rock, 3..5);
        assert_eq!(shares.range(card), Some(0..3));
        // The range stays while a chunk reads it, and is freed with the last.
        assert_eq!((shares.leave(bark), shares.leave(card)), (None, None));
        assert_eq!(shares.range(leaves), Some(0..3));
        assert_eq!(shares.leave(leaves), Some(0..3));
        assert_eq!(shares.leave(stone), Some(3..5));
        assert!(shares.buffers.is_empty() && shares.chunks.is_empty());
        assert_eq!(shares.leave(stone), None, "leaving twice frees nothing");
    }

    fn ranges(capacity: u32) -> Ranges {
        let mut r = Ranges::default();
        r.grow(capacity);
        r
    }

    #[test]
    fn ranges_are_taken_best_fit_and_merged_when_given_back() {
        let mut r = ranges(100);
        let a = r.take(10).unwrap();
        let b = r.take(20).unwrap();
        let c = r.take(30).unwrap();
        assert_eq!((a.clone(), b.clone(), c.clone()), (0..10, 10..30, 30..60));
        r.give(a);
        r.give(c);
        // Free: 0..10 and 30..100. Five fit best in the ten at the start.
        assert_eq!(r.take(5), Some(0..5));
        assert_eq!(r.take(50), Some(30..80));
        assert_eq!(r.take(30), None);
        r.give(b);
        // 5..30 is free again, one range with 5..10 (merged on both sides of 10).
        assert_eq!(r.take(25), Some(5..30));
        assert_eq!(r.take(21), None);
        assert_eq!(r.take(20), Some(80..100));
    }

    #[test]
    fn growing_frees_the_new_slots_merged_with_the_tail() {
        let mut r = ranges(10);
        let a = r.take(6).unwrap();
        assert_eq!(r.largest(), 4);
        r.grow(20);
        assert_eq!(r.largest(), 14);
        assert_eq!(r.take(14), Some(6..20));
        r.give(a);
        assert_eq!(r.take(6), Some(0..6));
        assert_eq!(r.take(1), None);
    }

    #[test]
    fn shrinks_by_halving_while_a_quarter_or_less_is_used() {
        let mut r = ranges(1024);
        let a = r.take(100).unwrap();
        // 100 of 1024: 512 (a fifth), 256 (two fifths); 128 would leave 28 free.
        assert_eq!(r.shrunk(16), Some(256));
        // Never under the floor.
        assert_eq!(r.shrunk(512), Some(512));
        assert_eq!(r.shrunk(1024), None);
        let _b = r.take(200).unwrap();
        // 300 of 1024 is more than a quarter: it stays.
        assert_eq!(r.shrunk(16), None);
        r.give(a);
        // 200 of 1024: half (a quarter is not more than 200 / 512).
        assert_eq!(r.shrunk(16), Some(512));
        assert_eq!(ranges(64).shrunk(16), Some(16));
    }

    #[test]
    fn packing_keeps_the_order_of_the_ranges_and_leaves_no_gaps() {
        let moves = packed([('c', 70..90), ('a', 5..15), ('b', 40..41)]);
        assert_eq!(
            moves,
            vec![('a', 5..15, 0), ('b', 40..41, 10), ('c', 70..90, 11)]
        );
        assert!(packed::<u8>([]).is_empty());
    }
}
