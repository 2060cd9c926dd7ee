//! Node/DoF map JSON.
#![no_main]

use jprom::io::dof_map::DofMap;
use jprom::memory::MemoryBudget;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    MemoryBudget::set_global(Some(MemoryBudget::new(256 << 20)));
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(map) = DofMap::parse(text, "fuzz") {
        for n in &map.nodes {
            let _ = map.node(n.id);
        }
    }
});
