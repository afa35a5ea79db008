// The shipped ode driver from outside the tree: its installed header
// compiles on its own (included first, nothing else of RoboTalk), and a
// driver built through the registry steps the physics.
#include <ode_driver.h>

#include <iostream>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  robotalk::DriverRegistry registry;
  robotalk::RegisterOdeDriver(registry);
  auto driver =
      registry.Create("ode", robotalk::DriverConfig{.robot_name = "p", .urdf_path = argv[1], .options = {}});
  auto& ode = static_cast<robotalk::OdeDriver&>(*driver);
  std::vector<robotalk::Completion> done;
  ode.Step(100, done);
  const std::optional<robotalk::walking::WalkStatus> walk = ode.walk_status();
  std::cout << "ode " << ode.model().name() << " " << ode.stats().steps << " steps"
            << (walk ? " walking" : " on wheels") << "\n";
  return ode.stats().steps == 100 ? 0 : 1;
}
