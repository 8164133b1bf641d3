import kodawari_native


def pytest_report_header(config):
    return f"kodawari_native {kodawari_native.__version__} from {kodawari_native.__file__}"
