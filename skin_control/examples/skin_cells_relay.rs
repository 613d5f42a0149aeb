//! Relays `skin_msgs/SkinCellArray` from one topic to another through r2r's Rust types: the
//! smallest r2r node of the project, used by the interoperability test (rclpy publishes, this
//! node decodes and re-encodes every field, rclpy checks what comes back). It starts relaying
//! once its output has a subscriber, so nothing is lost to discovery.
//!
//! `skin_cells_relay --input /skin/cells_in --output /skin/cells_out` (runs until interrupted: an
//! exit right after the last publish could drop samples that Fast DDS still sends
//! asynchronously).
use anyhow::Result;
use clap::Parser;
use futures::{executor::LocalPool, task::LocalSpawnExt, StreamExt};
use r2r::skin_msgs::msg::SkinCellArray;
use skin_control::qos;

#[derive(Parser)]
#[command(about = "Relay skin_msgs/SkinCellArray between two topics (r2r interop check)")]
struct Args {
    /// Topic to subscribe to.
    #[arg(long, default_value = "/skin/cells_in")]
    input: String,
    /// Topic to publish on.
    #[arg(long, default_value = "/skin/cells_out")]
    output: String,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, "skin_cells_relay", "")?;
    let mut sub = node.subscribe::<SkinCellArray>(&args.input, qos::stream())?;
    let publisher = node.create_publisher::<SkinCellArray>(&args.output, qos::stream())?;
    let mut pool = LocalPool::new();
    let output = args.output.clone();
    let matched = publisher.wait_for_inter_process_subscribers()?;
    pool.spawner().spawn_local(async move {
        // Discovery is not symmetric: a peer may already see our publisher while our writer has
        // not matched its reader yet, and a volatile writer drops what it sends before that. The
        // input waits meanwhile in the subscription's queue (10 messages).
        if let Err(e) = matched.await {
            eprintln!("skin_cells_relay: waiting for a subscriber on {output} failed: {e}");
            return;
        }
        while let Some(msg) = sub.next().await {
            if let Err(e) = publisher.publish(&msg) {
                eprintln!("skin_cells_relay: publish on {output} failed: {e}");
            }
        }
    })?;
    println!("skin_cells_relay: {} -> {}", args.input, args.output);
    loop {
        node.spin_once(std::time::Duration::from_millis(10));
        pool.run_until_stalled();
    }
}
