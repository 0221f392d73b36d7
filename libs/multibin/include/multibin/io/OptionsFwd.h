/* Part of the multibin elevation-mapping library. */
#pragma once

// What an options struct's read(), loadFromConfigFile() and saveToConfigFile() name, declared for
// the options headers, which the public map header includes: the configuration classes
// themselves are included only where the options are read.

namespace mrpt::config {
class CConfigFileBase;
}

namespace multibin {
class StrictConfigSection;
}
