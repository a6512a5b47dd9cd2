# Every external library, found once. Debian 12 packages (scripts/bootstrap installs them).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs calib3d features2d objdetect ximgproc video)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(spdlog REQUIRED)
find_package(Ceres 2 REQUIRED)  # pipeline/calib: bundle adjustment
find_package(opengv REQUIRED)   # pipeline/calib: minimal relative and absolute pose solvers with RANSAC
pkg_check_modules(LIBAV REQUIRED IMPORTED_TARGET libavcodec libavformat libavutil libswscale)
pkg_check_modules(LIBCAMERA REQUIRED IMPORTED_TARGET libcamera)  # drivers/libcamera (0.0.3 on Debian 12)
if(NOT TARGET PkgConfig::LIBUSB)
  pkg_check_modules(LIBUSB REQUIRED IMPORTED_TARGET libusb-1.0)  # drivers/ptp
endif()
if(PX_BUILD_TESTS AND NOT TARGET PkgConfig::UMOCKDEV)
  pkg_check_modules(UMOCKDEV REQUIRED IMPORTED_TARGET umockdev-1.0)  # emulated devices in driver tests
endif()
if(PX_BUILD_TESTS)
  # The LD_PRELOAD library umockdev test processes run under (tests set it via ctest ENVIRONMENT).
  find_library(PX_UMOCKDEV_PRELOAD NAMES libumockdev-preload.so.0 REQUIRED)
endif()
# capture reads wigglegrams' animated WebP files (FFmpeg 5.1 has no animated WebP decoder);
# the tests decode WebP clips back with it too.
pkg_check_modules(WEBPDEMUX REQUIRED IMPORTED_TARGET libwebpdemux)
# device/http: the web app's HTTP server (Debian builds cpp-httplib as a library), and the QR code
# that carries its access token to a phone.
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
pkg_check_modules(QRENCODE REQUIRED IMPORTED_TARGET libqrencode)
if(PX_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(PX_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
