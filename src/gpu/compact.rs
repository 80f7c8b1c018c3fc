//! Post-processing (paper §3.3, step PP) on wgpu: order-preserving compute
//! scans in place of Thrust's stream compaction. Shader: `shaders/compact.wgsl`.
//!
//! The empty-pixel list stays implicit: the exclusive scan of the empty counts
//! of the 32-pixel coverage words lets `throw.wgsl` find the i-th empty pixel
//! in index order, which is exactly the list that in-order compaction keeps.
//! The same scan gathers the survivors of conflict removal in dart order.

use super::util;

/// Elements one workgroup scans.
pub const BLOCK: u32 = 1024;

/// `struct ScanInfo` in `shaders/compact.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ScanInfo {
    n: u32,
    words: u32,
    pixels: u32,
    pad: u32,
}

/// The scan kernels.
pub struct CompactStage {
    layout: wgpu::BindGroupLayout,
    count_words: wgpu::ComputePipeline,
    scan_blocks: wgpu::ComputePipeline,
    add_sums: wgpu::ComputePipeline,
}

impl CompactStage {
    /// Compiles the kernels.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = util::layout(
            device,
            "compact",
            &[
                util::uniform(0, c),
                util::storage(1, c, false),
                util::storage(2, c, false),
            ],
        );
        let pl = util::pipeline_layout(device, &layout);
        let module = util::module(device, "compact.wgsl", util::SHADERS[4].1);
        Self {
            count_words: util::compute(device, &pl, &module, "count_words"),
            scan_blocks: util::compute(device, &pl, &module, "scan_blocks"),
            add_sums: util::compute(device, &pl, &module, "add_sums"),
            layout,
        }
    }
}

/// A multi-level exclusive scan over up to `capacity` elements: level 0 holds
/// the data, each next level the block totals of the one below, and the last
/// level, one element, the grand total.
pub struct ScanChain {
    /// Level buffers; `levels[0]` is the data.
    pub levels: Vec<wgpu::Buffer>,
    infos: Vec<wgpu::Buffer>,
    groups: Vec<wgpu::BindGroup>,
    /// The bind group of `count_words` (coverage in, counts into level 0).
    count_group: Option<wgpu::BindGroup>,
    capacity: u32,
}

fn level_sizes(n0: u32, levels: usize) -> Vec<u32> {
    let mut sizes = vec![n0];
    while sizes.len() < levels {
        let last = sizes[sizes.len() - 1];
        sizes.push(last.div_ceil(BLOCK).max(1));
    }
    sizes
}

impl ScanChain {
    /// Allocates a chain for `capacity` elements. With `coverage`, the chain
    /// also counts the empty pixels of each coverage word into level 0.
    pub fn new(
        device: &wgpu::Device,
        stage: &CompactStage,
        label: &str,
        capacity: u32,
        coverage: Option<&wgpu::Buffer>,
    ) -> Self {
        let mut count = 1;
        let mut last = capacity;
        while last > 1 || count < 2 {
            last = last.div_ceil(BLOCK).max(1);
            count += 1;
            if last == 1 {
                break;
            }
        }
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let sizes = level_sizes(capacity, count);
        let levels: Vec<_> = sizes
            .iter()
            .map(|&n| util::buffer_of(device, label, 4 * u64::from(n), usage))
            .collect();
        let infos: Vec<_> = sizes
            .iter()
            .map(|_| {
                util::buffer_of(
                    device,
                    label,
                    16,
                    wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                )
            })
            .collect();
        let groups = (0..count - 1)
            .map(|i| {
                util::bind_group(
                    device,
                    &stage.layout,
                    &[
                        infos[i].as_entire_binding(),
                        levels[i].as_entire_binding(),
                        levels[i + 1].as_entire_binding(),
                    ],
                )
            })
            .collect();
        let count_group = coverage.map(|cov| {
            util::bind_group(
                device,
                &stage.layout,
                &[
                    infos[0].as_entire_binding(),
                    cov.as_entire_binding(),
                    levels[0].as_entire_binding(),
                ],
            )
        });
        Self {
            levels,
            infos,
            groups,
            count_group,
            capacity,
        }
    }

    /// Elements the chain can scan.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// The buffer whose first element is the grand total after a scan.
    pub fn total(&self) -> &wgpu::Buffer {
        &self.levels[self.levels.len() - 1]
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        self.levels.iter().map(wgpu::Buffer::size).sum()
    }

    /// Sets the number of elements of the next scan (`pixels` for counting).
    pub fn set_len(&self, queue: &wgpu::Queue, n0: u32, pixels: u32) {
        for (info, &n) in self.infos.iter().zip(&level_sizes(n0, self.levels.len())) {
            let v = ScanInfo {
                n,
                words: n0,
                pixels,
                pad: 0,
            };
            queue.write_buffer(info, 0, bytemuck::bytes_of(&v));
        }
    }

    /// Counts the empty pixels per coverage word into level 0 (`n0` words).
    pub fn encode_count(&self, pass: &mut wgpu::ComputePass<'_>, stage: &CompactStage, n0: u32) {
        if let Some(g) = &self.count_group {
            pass.set_pipeline(&stage.count_words);
            pass.set_bind_group(0, g, &[]);
            util::dispatch(pass, n0.div_ceil(256));
        }
    }

    /// Scans the first `n0` elements of level 0 in place.
    pub fn encode_scan(&self, pass: &mut wgpu::ComputePass<'_>, stage: &CompactStage, n0: u32) {
        let sizes = level_sizes(n0, self.levels.len());
        pass.set_pipeline(&stage.scan_blocks);
        for (i, g) in self.groups.iter().enumerate() {
            pass.set_bind_group(0, g, &[]);
            util::dispatch(pass, sizes[i].div_ceil(BLOCK));
        }
        pass.set_pipeline(&stage.add_sums);
        for i in (0..self.groups.len().saturating_sub(1)).rev() {
            pass.set_bind_group(0, &self.groups[i], &[]);
            util::dispatch(pass, sizes[i].div_ceil(BLOCK));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::level_sizes;

    #[test]
    fn levels_end_in_a_single_total() {
        assert_eq!(level_sizes(5000, 3), vec![5000, 5, 1]);
        assert_eq!(level_sizes(10, 3), vec![10, 1, 1]);
    }
}
